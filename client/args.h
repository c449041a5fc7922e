// Hand-rolled parsing of a subcommand's flags: `--flag value`, `--flag=value`
// and boolean switches `--flag` (or `--flag=true|false`). Subcommands do not
// use global absl flags, so each one declares exactly what it accepts.
//
//   ASSIGN_OR_RETURN(ParsedArgs a, ParseArgs(args, {"map", "resolution"}, {"local"}));
//   std::string map = a.Get("map").value_or("");
//   ASSIGN_OR_RETURN(std::optional<double> res, a.GetDouble("resolution"));
//
// Thread-safety: plain value types and free functions.
#ifndef COVPLAN_CLIENT_ARGS_H_
#define COVPLAN_CLIENT_ARGS_H_

#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "planner/common/json_text.h"
#include "planner/tour/robot_model.h"

namespace covplan {

struct ParsedArgs {
  std::map<std::string, std::string> values;                 // flag name (without --) -> value
  std::set<std::string> switches;                            // boolean flags that are on
  std::map<std::string, std::vector<std::string>> repeated;  // repeatable flags, in order

  std::optional<std::string> Get(const std::string& name) const;
  bool Has(const std::string& name) const { return switches.count(name) != 0; }
  // InvalidArgument when present but not a number (or not finite).
  absl::StatusOr<std::optional<double>> GetDouble(const std::string& name) const;
  absl::StatusOr<std::optional<int64_t>> GetInt(const std::string& name) const;
};

// InvalidArgument on unknown flags, a missing value, a repeated flag (other
// than one of `repeatable_flags`) or a positional argument.
absl::StatusOr<ParsedArgs> ParseArgs(const std::vector<std::string>& args,
                                     const std::set<std::string>& value_flags,
                                     const std::set<std::string>& bool_flags,
                                     const std::set<std::string>& repeatable_flags = {});

// `text`, the value of --`flag`, as one of `choices` (named in the order
// the error lists them); else InvalidArgument "--flag must be a, b or c,
// got 'text'".
template <typename T>
absl::StatusOr<T> ParseChoice(const char* flag, const std::string& text,
                              const std::vector<std::pair<std::string, T>>& choices) {
  std::string names;
  for (size_t i = 0; i < choices.size(); ++i) {
    if (choices[i].first == text) return choices[i].second;
    absl::StrAppend(&names,
                    i == 0                    ? ""
                    : i + 1 == choices.size() ? " or "
                                              : ", ",
                    choices[i].first);
  }
  return absl::InvalidArgumentError(
      absl::StrCat("--", flag, " must be ", names, ", got '", text, "'"));
}

// The whole file a flag names; InvalidArgument "--FLAG PATH: cannot read it".
absl::StatusOr<std::string> ReadFlagFile(const std::string& flag, const std::string& path);

// Writes `contents` to `path` (replacing it); InvalidArgument when it cannot
// be opened, Internal when the write fails.
absl::Status WriteTextFile(const std::string& path, const std::string& contents);

// "X,Y" or "X,Y,THETA", finite numbers (theta 0 when absent); nullopt
// otherwise. The pose flags (--start, --end, --robot) read poses with it.
std::optional<Pose2> ParseXyTheta(const std::string& text);

// Shared main of a subcommand: prints `usage` for --help/-h, else runs
// `run(args)` and maps its status to an exit code (errors on stderr, prefixed
// with "covplan <name>: ").
int RunSubcommand(const char* name, const char* usage, const std::vector<std::string>& args,
                  absl::Status (*run)(const std::vector<std::string>&));

}  // namespace covplan

#endif  // COVPLAN_CLIENT_ARGS_H_
