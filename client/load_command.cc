#include "client/load_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "client/args.h"
#include "client/remote.h"
#include "planner/common/status_macros.h"
#include "api/convert.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan load --server HOST:PORT --map FILE [--concurrency N] [--duration S]\n"
    "                    [--deadline-ms D] [--resolution M] [--tool-width M]\n"
    "                    [--time-limit S] [--tour gtsp|greedy] [--backoff-ms B]\n";

double Percentile(std::vector<double> sorted, double q) {
  if (sorted.empty()) return 0.0;
  const size_t rank = static_cast<size_t>(std::ceil(q * sorted.size()));
  return sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
}

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(ParsedArgs a,
                   ParseArgs(args,
                             {"server", "map", "concurrency", "duration", "deadline-ms",
                              "resolution", "tool-width", "time-limit", "tour", "backoff-ms"},
                             {}));
  if (!a.Get("server")) return absl::InvalidArgumentError("--server HOST:PORT is required");
  if (!a.Get("map")) return absl::InvalidArgumentError("--map FILE is required");
  ASSIGN_OR_RETURN(std::optional<int64_t> concurrency, a.GetInt("concurrency"));
  ASSIGN_OR_RETURN(std::optional<double> duration, a.GetDouble("duration"));
  ASSIGN_OR_RETURN(std::optional<int64_t> deadline_ms, a.GetInt("deadline-ms"));
  ASSIGN_OR_RETURN(std::optional<int64_t> backoff_ms, a.GetInt("backoff-ms"));
  ASSIGN_OR_RETURN(std::optional<double> tool, a.GetDouble("tool-width"));
  ASSIGN_OR_RETURN(std::optional<double> limit, a.GetDouble("time-limit"));
  MapFileOverrides overrides;
  ASSIGN_OR_RETURN(overrides.resolution, a.GetDouble("resolution"));
  const int threads = static_cast<int>(concurrency.value_or(4));
  if (threads < 1 || threads > 1024) return absl::InvalidArgumentError("--concurrency must be in [1, 1024]");
  const double seconds = duration.value_or(10.0);
  if (!(seconds > 0 && seconds <= 24 * 3600)) return absl::InvalidArgumentError("--duration must be in (0, 86400]");
  const int64_t deadline = deadline_ms.value_or(1000);
  if (deadline <= 0) return absl::InvalidArgumentError("--deadline-ms must be positive");

  const std::string server = *a.Get("server");
  ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(*a.Get("map"), overrides, InputLimits()));
  std::unique_ptr<RemotePlanner> remote = RemotePlanner::Connect(server);
  v1::PutMapRequest put;
  *put.mutable_map() = map;
  put.set_name(*a.Get("map"));
  absl::StatusOr<v1::PutMapResponse> stored = remote->PutMap(put, absl::Seconds(60));
  if (!stored.ok()) {
    return absl::Status(stored.status().code(),
                        absl::StrCat("PutMap to ", server, " failed: ",
                                     absl::StatusCodeToString(stored.status().code()), ": ",
                                     stored.status().message()));
  }
  v1::PlanRequest request;
  request.set_map_id(stored->map_id());
  request.mutable_robot()->set_tool_width_m(tool.value_or(0.8));
  if (limit) request.set_time_limit_s(*limit);
  if (auto t = a.Get("tour")) request.set_tour_solver(*t == "greedy" ? v1::GREEDY : v1::GTSP);

  LoadReport report;
  report.concurrency = threads;
  report.deadline_ms = deadline;
  absl::Mutex mu;
  const absl::Time start = absl::Now();
  const absl::Time end = start + absl::Seconds(seconds);
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t) {
    workers.emplace_back([&] {
      while (absl::Now() < end) {
        const absl::Time sent = absl::Now();
        absl::StatusOr<v1::PlanResponse> reply = remote->Plan(request, absl::Milliseconds(deadline));
        const double ms = absl::ToDoubleMilliseconds(absl::Now() - sent);
        {
          absl::MutexLock lock(&mu);
          ++report.requests;
          ++report.codes[absl::StatusCodeToString(reply.status().code())];
          report.latencies_ms.push_back(ms);
          if (reply.ok()) {
            ++report.ok;
            report.cut_short += reply->stats().tour_cut_short();
          }
          if (ms > static_cast<double>(deadline)) ++report.late;
        }
        // Back off briefly after a refusal so an overloaded server is probed,
        // not hammered.
        if (absl::IsResourceExhausted(reply.status())) {
          absl::SleepFor(absl::Milliseconds(backoff_ms.value_or(10)));
        }
      }
    });
  }
  for (std::thread& w : workers) w.join();
  report.duration_s = absl::ToDoubleSeconds(absl::Now() - start);
  std::printf("%s\n", report.ToJson().c_str());
  return absl::OkStatus();
}

}  // namespace

std::string LoadReport::ToJson() const {
  std::vector<double> sorted = latencies_ms;
  std::sort(sorted.begin(), sorted.end());
  std::string codes_json;
  for (const auto& [code, count] : codes) {
    absl::StrAppend(&codes_json, codes_json.empty() ? "" : ", ", "\"", code, "\": ", count);
  }
  return absl::StrFormat(
      "{\"requests\": %d, \"ok\": %d, \"codes\": {%s}, \"p50_ms\": %.2f, \"p95_ms\": %.2f, "
      "\"p99_ms\": %.2f, \"max_ms\": %.2f, \"late\": %d, \"cut_short\": %d, "
      "\"concurrency\": %d, \"deadline_ms\": %d, \"duration_s\": %.2f, \"throughput_rps\": %.2f}",
      requests, ok, codes_json, Percentile(sorted, 0.50), Percentile(sorted, 0.95),
      Percentile(sorted, 0.99), sorted.empty() ? 0.0 : sorted.back(), late, cut_short,
      concurrency, deadline_ms, duration_s, duration_s > 0 ? requests / duration_s : 0.0);
}

int RunLoadCommand(const std::vector<std::string>& args) {
  return RunSubcommand("load", kUsage, args, &Run);
}

}  // namespace covplan
