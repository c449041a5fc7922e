// The line format of the server's small configuration files (the token file,
// the tenant quota file): one entry per line of whitespace-separated fields,
// blank lines and lines starting with '#' skipped; errors name the line.
//
//   RETURN_IF_ERROR(ForEachConfigLine(text, [&](std::vector<absl::string_view> fields) {
//     if (fields.size() != 2) return absl::InvalidArgumentError("expected two fields");
//     return absl::OkStatus();
//   }));
//   ASSIGN_OR_RETURN(std::string text, ReadConfigFile("--token_file", path));
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_SERVER_CONFIG_LINES_H_
#define COVPLAN_SERVER_CONFIG_LINES_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace covplan {

// Calls `entry` with the fields of each entry line of `text`; its first
// error is returned as InvalidArgument "line N: <message>".
absl::Status ForEachConfigLine(
    absl::string_view text,
    const std::function<absl::Status(const std::vector<absl::string_view>& fields)>& entry);

// The whole file; InvalidArgument "<flag> <path>: cannot read it" when it
// cannot be read.
absl::StatusOr<std::string> ReadConfigFile(absl::string_view flag, const std::string& path);

}  // namespace covplan

#endif  // COVPLAN_SERVER_CONFIG_LINES_H_
