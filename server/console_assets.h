// The web console's files (server/console/), compiled into the server by
// cmake/embed_assets.cmake, so the page works offline with nothing
// installed beside the binary.
//
//   for (const ConsoleAsset& a : ConsoleAssets()) if (a.path == "/index.html") ...
//
// Thread-safety: immutable after first use.
#ifndef COVPLAN_SERVER_CONSOLE_ASSETS_H_
#define COVPLAN_SERVER_CONSOLE_ASSETS_H_

#include <cstddef>
#include <vector>

#include "absl/strings/string_view.h"

namespace covplan {

struct ConsoleAsset {
  absl::string_view path;          // "/index.html", "/console.js", ...
  absl::string_view content_type;  // "text/html; charset=utf-8", ...
  const char* data;
  size_t size;
};

const std::vector<ConsoleAsset>& ConsoleAssets();

}  // namespace covplan

#endif  // COVPLAN_SERVER_CONSOLE_ASSETS_H_
