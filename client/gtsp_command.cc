#include "client/gtsp_command.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/gtsp/gtsplib.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan gtsp FILE [--time-limit SECONDS] [--seed N] [--threads N]\n"
    "                         [--effort fast|default|thorough] [--search hybrid|lns|memetic]\n"
    "Solves a GTSPLIB instance and prints one JSON object on stdout.\n"
    "With --time-limit the solver keeps improving until the limit (effort\n"
    "thorough unless --effort is given); without it, it stops on its own.\n"
    "--search picks the search that fills a thorough deadline (default hybrid).\n";

int UsageError(const std::string& message) {
  std::cerr << "covplan gtsp: " << message << "\n" << kUsage;
  return 2;
}

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

struct Args {
  std::string file;
  std::optional<double> time_limit_s;
  uint64_t seed = 1;
  int threads = 1;
  std::optional<GtspEffort> effort;
  GtspSearch search = GtspSearch::kHybrid;
};

// Returns an error message, or "" on success; sets `help` for --help.
std::string ParseArgs(const std::vector<std::string>& args, Args& out, bool& help) {
  help = false;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string arg = args[i];
    if (arg == "-h" || arg == "--help") {
      help = true;
      return "";
    }
    if (arg.rfind("--", 0) != 0) {
      if (!out.file.empty()) return absl::StrCat("unexpected argument '", arg, "'");
      out.file = arg;
      continue;
    }
    std::string value;
    if (size_t eq = arg.find('='); eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
    } else {
      if (i + 1 >= args.size()) return absl::StrCat(arg, " needs a value");
      value = args[++i];
    }
    if (arg == "--time-limit") {
      double s = 0;
      if (!absl::SimpleAtod(value, &s) || !std::isfinite(s) || s <= 0) {
        return absl::StrCat("--time-limit must be a positive number of seconds, got '", value, "'");
      }
      out.time_limit_s = s;
    } else if (arg == "--seed") {
      if (!absl::SimpleAtoi(value, &out.seed))
        return absl::StrCat("--seed must be a non-negative integer, got '", value, "'");
    } else if (arg == "--threads") {
      if (!absl::SimpleAtoi(value, &out.threads) || out.threads < 1 || out.threads > 256) {
        return absl::StrCat("--threads must be an integer in [1, 256], got '", value, "'");
      }
    } else if (arg == "--effort") {
      if (value == "fast") {
        out.effort = GtspEffort::kFast;
      } else if (value == "default") {
        out.effort = GtspEffort::kDefault;
      } else if (value == "thorough") {
        out.effort = GtspEffort::kThorough;
      } else {
        return absl::StrCat("--effort must be fast, default or thorough, got '", value, "'");
      }
    } else if (arg == "--search") {
      if (value == "hybrid") {
        out.search = GtspSearch::kHybrid;
      } else if (value == "lns") {
        out.search = GtspSearch::kLns;
      } else if (value == "memetic") {
        out.search = GtspSearch::kMemetic;
      } else {
        return absl::StrCat("--search must be hybrid, lns or memetic, got '", value, "'");
      }
    } else {
      return absl::StrCat("unknown flag '", arg, "'");
    }
  }
  if (out.file.empty()) return "missing instance FILE";
  return "";
}

}  // namespace

int RunGtspCommand(const std::vector<std::string>& args) {
  Args a;
  bool help = false;
  if (std::string err = ParseArgs(args, a, help); !err.empty()) return UsageError(err);
  if (help) {
    std::cout << kUsage;
    return 0;
  }
  absl::StatusOr<GtspLibFile> file = LoadGtspLibFile(a.file);
  if (!file.ok()) {
    std::cerr << "covplan gtsp: " << file.status().message() << "\n";
    return 2;
  }
  GtspOptions opt;
  opt.seed = a.seed;
  opt.num_threads = a.threads;
  opt.search = a.search;
  opt.effort = a.effort.value_or(a.time_limit_s ? GtspEffort::kThorough : GtspEffort::kDefault);
  if (a.time_limit_s) opt.stop = StopToken::WithTimeout(absl::Seconds(*a.time_limit_s));
  absl::StatusOr<GtspResult> r = SolveGtsp(file->instance, opt);
  if (!r.ok()) {
    std::cerr << "covplan gtsp: " << r.status().message() << "\n";
    return absl::IsInvalidArgument(r.status()) ? 2 : 1;
  }
  std::ostringstream json;
  json << "{\"instance\":" << JsonString(file->name) << ",\"cost\":" << std::llround(r->cost)
       << ",\"tour\":[";
  for (size_t i = 0; i < r->tour.size(); ++i) json << (i ? "," : "") << r->tour[i] + 1;
  json << "],\"time_s\":" << absl::StrCat(r->elapsed_s) << ",\"iterations\":" << r->iterations
       << ",\"stopped_early\":" << (r->stopped_early ? "true" : "false") << "}\n";
  std::cout << json.str();
  std::cout.flush();
  return 0;
}

}  // namespace covplan
