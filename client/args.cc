#include "client/args.h"

#include <cstdio>
#include <cstdlib>

#include <cmath>
#include <fstream>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace covplan {

std::optional<std::string> ParsedArgs::Get(const std::string& name) const {
  auto it = values.find(name);
  if (it == values.end()) return std::nullopt;
  return it->second;
}

absl::StatusOr<std::optional<double>> ParsedArgs::GetDouble(const std::string& name) const {
  std::optional<std::string> text = Get(name);
  if (!text) return std::optional<double>();
  double value = 0;
  if (!absl::SimpleAtod(*text, &value) || !std::isfinite(value)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, " expects a number, got '", *text, "'"));
  }
  return std::optional<double>(value);
}

absl::StatusOr<std::optional<int64_t>> ParsedArgs::GetInt(const std::string& name) const {
  std::optional<std::string> text = Get(name);
  if (!text) return std::optional<int64_t>();
  int64_t value = 0;
  if (!absl::SimpleAtoi(*text, &value)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, " expects an integer, got '", *text, "'"));
  }
  return std::optional<int64_t>(value);
}

absl::StatusOr<ParsedArgs> ParseArgs(const std::vector<std::string>& args,
                                     const std::set<std::string>& value_flags,
                                     const std::set<std::string>& bool_flags,
                                     const std::set<std::string>& repeatable_flags) {
  ParsedArgs parsed;
  std::set<std::string> seen;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) {
      return absl::InvalidArgumentError(absl::StrCat("unexpected argument '", arg, "'"));
    }
    std::string name = arg.substr(2);
    std::optional<std::string> value;
    if (size_t eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    if (repeatable_flags.count(name) != 0) {
      if (!value) {
        if (i + 1 >= args.size()) {
          return absl::InvalidArgumentError(absl::StrCat("--", name, " needs a value"));
        }
        value = args[++i];
      }
      parsed.repeated[name].push_back(*value);
      continue;
    }
    if (!seen.insert(name).second) {
      return absl::InvalidArgumentError(absl::StrCat("--", name, " given more than once"));
    }
    if (value_flags.count(name) != 0) {
      if (!value) {
        if (i + 1 >= args.size()) {
          return absl::InvalidArgumentError(absl::StrCat("--", name, " needs a value"));
        }
        value = args[++i];
      }
      parsed.values[name] = *value;
    } else if (bool_flags.count(name) != 0) {
      if (!value || *value == "true" || *value == "1") {
        parsed.switches.insert(name);
      } else if (*value != "false" && *value != "0") {
        return absl::InvalidArgumentError(
            absl::StrCat("--", name, " is a switch: use --", name, " or --", name, "=false"));
      }
    } else {
      return absl::InvalidArgumentError(absl::StrCat("unknown flag --", name));
    }
  }
  return parsed;
}

int RunSubcommand(const char* name, const char* usage, const std::vector<std::string>& args,
                  absl::Status (*run)(const std::vector<std::string>&)) {
  for (const std::string& arg : args) {
    if (arg == "--help" || arg == "-h") {
      std::fputs(usage, stdout);
      return 0;
    }
  }
  const absl::Status status = run(args);
  if (status.ok()) return 0;
  std::fprintf(stderr, "covplan %s: %s\n", name, std::string(status.message()).c_str());
  return 1;
}

absl::Status WriteTextFile(const std::string& path, const std::string& contents) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return absl::InvalidArgumentError(absl::StrCat("cannot open ", path, " for writing"));
  out << contents;
  out.close();
  if (!out) return absl::InternalError(absl::StrCat("cannot write ", path));
  return absl::OkStatus();
}

absl::StatusOr<std::string> ReadFlagFile(const std::string& flag, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in)
    return absl::InvalidArgumentError(absl::StrCat("--", flag, " ", path, ": cannot read it"));
  return text.str();
}

std::optional<Pose2> ParseXyTheta(const std::string& text) {
  std::vector<double> v;
  size_t begin = 0;
  while (true) {
    const size_t comma = text.find(',', begin);
    const std::string part =
        text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    char* end = nullptr;
    const double d = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(d)) {
      return std::nullopt;
    }
    v.push_back(d);
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  if (v.size() < 2 || v.size() > 3) return std::nullopt;
  return Pose2{v[0], v[1], v.size() == 3 ? v[2] : 0.0};
}

}  // namespace covplan
