// One-line structured logs on stderr: `ts=... level=info msg="..." k=v ...`.
//
//   LogLine("info", "plan finished", {{"req", id}, {"code", "OK"}});
//
// Values longer than kMaxLogValueBytes are cut (with their full size noted),
// so no request can make the server write megabyte log lines.
//
// Thread-safety: each line is written with a single fwrite, so lines from
// different threads do not interleave.
#ifndef COVPLAN_SERVER_LOG_H_
#define COVPLAN_SERVER_LOG_H_

#include <cstdio>
#include <initializer_list>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace covplan {

inline constexpr size_t kMaxLogValueBytes = 512;

inline void LogLine(absl::string_view level, absl::string_view message,
                    std::initializer_list<std::pair<absl::string_view, std::string>> fields = {}) {
  std::string line = absl::StrCat(
      "ts=", absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone()),
      " level=", level, " msg=\"", message, "\"");
  for (const auto& [key, value] : fields) {
    std::string text = value.size() <= kMaxLogValueBytes
                           ? value
                           : absl::StrCat(absl::string_view(value).substr(0, kMaxLogValueBytes),
                                          "...(", value.size(), " bytes)");
    const bool quote = text.empty() || text.find_first_of(" \"=") != std::string::npos;
    for (char& c : text) {
      if (c == '"') c = '\'';  // keep the quoted value parseable
      if (c == '\n') c = ' ';
    }
    absl::StrAppend(&line, " ", key, "=", quote ? "\"" : "", text, quote ? "\"" : "");
  }
  line += '\n';
  std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace covplan

#endif  // COVPLAN_SERVER_LOG_H_
