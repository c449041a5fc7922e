#include "client/load_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "client/args.h"
#include "client/local_engine.h"
#include "client/remote.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan load --server HOST:PORT (--map FILE | --maps DIR|F1,F2,...)\n"
    "                   [--tls-ca PEM] [--tls-cert PEM --tls-key PEM] [--token T | --token-file "
    "F]\n"
    "                    [--concurrency N] [--duration S] [--requests N]\n"
    "                    [--deadline-ms D] [--resolution M] [--tool-width M]\n"
    "                    [--time-limit S] [--tour gtsp|greedy] [--backoff-ms B]\n"
    "                    [--zipf S] [--seed N] [--inline] [--random-start]\n"
    "                    [--full-replies] [--rate R]\n"
    "--maps: every *.yaml and *.geojson in DIR (sorted), or a comma list; each\n"
    "request picks one, map k (0-based, in that order) with weight 1/(k+1)^S\n"
    "(--zipf 0: uniform). --inline sends the map in every request instead of\n"
    "PutMap once and plan by id (any replica can then serve any map).\n"
    "--requests N stops after N requests (or --duration, whichever is first).\n"
    "--rate R paces the requests at R per second in all (worker t of N sends its\n"
    "k-th at (k N + t) / R s); a worker whose reply comes later sends at once.\n"
    "--random-start: each request starts at a free cell drawn uniformly (seeded by\n"
    "--seed) from the cells the robot can reach, heading uniform in [0, 2 pi).\n"
    "Replies are received in full but only their stats are decoded, so that the\n"
    "load client's own CPU stays small; --full-replies decodes every reply.\n";

// The centres of the cells a robot of `tool` width can reach on `map`: the
// engine's own drive grid, built locally.
absl::StatusOr<std::vector<Point2>> ReachableCellCentres(const v1::Map& map, double tool) {
  const EngineLimits limits;
  const LocalEngine local(limits);
  PlanRequest request;
  request.common.robot.tool_width_m = tool;
  ASSIGN_OR_RETURN(std::shared_ptr<const CoverageArea> area,
                   local.engine().AreaFor(MapSourceFor(map, limits), request));
  std::vector<Point2> centres;
  const Grid& drive = *area->drive;
  for (int r = 0; r < drive.rows(); ++r) {
    for (int c = 0; c < drive.cols(); ++c) {
      if (drive.IsFree(r, c)) centres.push_back(drive.CellCenter(r, c));
    }
  }
  if (centres.empty())
    return absl::InvalidArgumentError("--random-start: the map has no reachable cell");
  return centres;
}

std::string SourceName(v1::PlanSource s) {
  switch (s) {
    case v1::PLAN_SOURCE_COLD:
      return "cold";
    case v1::PLAN_SOURCE_CACHE_HIT:
      return "cache_hit";
    case v1::PLAN_SOURCE_IMPROVED:
      return "improved";
    case v1::PLAN_SOURCE_WARM_START:
      return "warm_start";
    default:
      return "unspecified";
  }
}

// The files of --maps: a directory's *.yaml / *.geojson (sorted) or a list.
absl::StatusOr<std::vector<std::string>> MapFiles(const std::string& spec) {
  std::vector<std::string> files;
  std::error_code error;
  if (std::filesystem::is_directory(spec, error)) {
    for (const auto& entry : std::filesystem::directory_iterator(spec, error)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".yaml" || ext == ".geojson") files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
  } else {
    for (absl::string_view f : absl::StrSplit(spec, ',', absl::SkipEmpty())) files.emplace_back(f);
  }
  if (files.empty())
    return absl::InvalidArgumentError(absl::StrCat("--maps ", spec, ": no map files"));
  return files;
}

double Percentile(std::vector<double> sorted, double q) {
  if (sorted.empty()) return 0.0;
  const size_t rank = static_cast<size_t>(std::ceil(q * sorted.size()));
  return sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// The flags of one load run, checked.
struct LoadFlags {
  std::string server;
  std::optional<double> zipf;
  std::optional<int64_t> seed;
  std::optional<int64_t> max_requests;
  std::optional<int64_t> backoff_ms;
  std::optional<double> tool;
  std::optional<double> limit;
  std::optional<std::string> tour;
  std::optional<double> rate;  // requests per second in all
  MapFileOverrides overrides;
  int threads = 4;
  double seconds = 10.0;
  int64_t deadline = 1000;
  bool send_inline = false;
  bool random_start = false;
  bool full_replies = false;
};

absl::StatusOr<LoadFlags> ParseLoadFlags(const ParsedArgs& a) {
  if (!a.Get("server")) return absl::InvalidArgumentError("--server HOST:PORT is required");
  if (!a.Get("map") == !a.Get("maps")) {
    return absl::InvalidArgumentError("exactly one of --map FILE or --maps DIR|LIST is required");
  }
  LoadFlags f;
  ASSIGN_OR_RETURN(f.zipf, a.GetDouble("zipf"));
  ASSIGN_OR_RETURN(f.seed, a.GetInt("seed"));
  ASSIGN_OR_RETURN(f.max_requests, a.GetInt("requests"));
  if (f.zipf && !(*f.zipf >= 0 && *f.zipf <= 10))
    return absl::InvalidArgumentError("--zipf must be in [0, 10]");
  if (f.max_requests && *f.max_requests <= 0)
    return absl::InvalidArgumentError("--requests must be positive");
  ASSIGN_OR_RETURN(std::optional<int64_t> concurrency, a.GetInt("concurrency"));
  ASSIGN_OR_RETURN(std::optional<double> duration, a.GetDouble("duration"));
  ASSIGN_OR_RETURN(std::optional<int64_t> deadline_ms, a.GetInt("deadline-ms"));
  ASSIGN_OR_RETURN(f.backoff_ms, a.GetInt("backoff-ms"));
  ASSIGN_OR_RETURN(f.rate, a.GetDouble("rate"));
  if (f.rate && !(*f.rate > 0 && *f.rate <= 1e6))
    return absl::InvalidArgumentError("--rate must be in (0, 1000000] requests per second");
  ASSIGN_OR_RETURN(f.tool, a.GetDouble("tool-width"));
  ASSIGN_OR_RETURN(f.limit, a.GetDouble("time-limit"));
  ASSIGN_OR_RETURN(f.overrides.resolution, a.GetDouble("resolution"));
  f.threads = static_cast<int>(concurrency.value_or(4));
  if (f.threads < 1 || f.threads > 1024)
    return absl::InvalidArgumentError("--concurrency must be in [1, 1024]");
  f.seconds = duration.value_or(10.0);
  if (!(f.seconds > 0 && f.seconds <= 24 * 3600))
    return absl::InvalidArgumentError("--duration must be in (0, 86400]");
  f.deadline = deadline_ms.value_or(1000);
  if (f.deadline <= 0) return absl::InvalidArgumentError("--deadline-ms must be positive");
  f.server = *a.Get("server");
  f.tour = a.Get("tour");
  f.send_inline = a.Has("inline");
  f.random_start = a.Has("random-start");
  f.full_replies = a.Has("full-replies");
  return f;
}

// One prepared request per map, in the order of the map files.
struct PreparedMaps {
  std::vector<v1::PlanRequest> requests;
  std::vector<std::string> acknowledged;         // map ids PutMap returned (not with --inline)
  std::vector<std::vector<Point2>> start_cells;  // per map, with --random-start
};

absl::StatusOr<PreparedMaps> PrepareMaps(const LoadFlags& f, const std::vector<std::string>& files,
                                         RemotePlanner* remote) {
  PreparedMaps out;
  for (const std::string& file : files) {
    ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(file, f.overrides, EngineLimits()));
    if (f.random_start) {
      ASSIGN_OR_RETURN(std::vector<Point2> cells, ReachableCellCentres(map, f.tool.value_or(0.8)));
      out.start_cells.push_back(std::move(cells));
    }
    v1::PlanRequest request;
    if (f.send_inline) {
      *request.mutable_map() = std::move(map);
    } else {
      v1::PutMapRequest put;
      *put.mutable_map() = std::move(map);
      put.set_name(file);
      absl::StatusOr<v1::PutMapResponse> stored = remote->PutMap(put, absl::Seconds(60));
      if (!stored.ok()) {
        return absl::Status(stored.status().code(),
                            absl::StrCat("PutMap of ", file, " to ", f.server, " failed: ",
                                         absl::StatusCodeToString(stored.status().code()), ": ",
                                         stored.status().message()));
      }
      request.set_map_id(stored->map_id());
      out.acknowledged.push_back(stored->map_id());
    }
    request.mutable_robot()->set_tool_width_m(f.tool.value_or(0.8));
    if (f.limit) request.set_time_limit_s(*f.limit);
    if (f.tour) request.set_tour_solver(*f.tour == "greedy" ? v1::GREEDY : v1::GTSP);
    out.requests.push_back(std::move(request));
  }
  return out;
}

// Sends the prepared requests from `flags.threads` workers until the
// duration or the request count runs out, and tallies the replies.
// Thread-compatible: one Run() per instance; the workers share `remote`.
class LoadRun {
 public:
  LoadRun(const LoadFlags& flags, const PreparedMaps& maps, RemotePlanner* remote)
      : flags_(flags), maps_(maps), remote_(remote) {
    for (size_t k = 0; k < maps_.requests.size(); ++k) {
      weights_.push_back(1.0 / std::pow(static_cast<double>(k + 1), flags_.zipf.value_or(0.0)));
    }
  }

  LoadReport Run() {
    report_.concurrency = flags_.threads;
    report_.deadline_ms = flags_.deadline;
    report_.maps = static_cast<int>(maps_.requests.size());
    report_.map_ids = maps_.acknowledged;
    report_.random_start = flags_.random_start;
    const absl::Time start = absl::Now();
    end_ = start + absl::Seconds(flags_.seconds);
    std::vector<std::thread> workers;
    for (int t = 0; t < flags_.threads; ++t) workers.emplace_back([this, t] { Work(t); });
    for (std::thread& w : workers) w.join();
    report_.duration_s = absl::ToDoubleSeconds(absl::Now() - start);
    return report_;
  }

 private:
  // False once --requests requests have been issued.
  bool TakeTicket() {
    if (!flags_.max_requests) return true;
    absl::MutexLock lock(&mu_);
    if (issued_ >= *flags_.max_requests) return false;
    ++issued_;
    return true;
  }

  // Map k's request, from a random reachable start with --random-start.
  v1::PlanRequest RequestFor(size_t k, std::mt19937_64& rng) const {
    v1::PlanRequest request = maps_.requests[k];
    if (flags_.random_start) {
      const std::vector<Point2>& cells = maps_.start_cells[k];
      const Point2 p = cells[std::uniform_int_distribution<size_t>(0, cells.size() - 1)(rng)];
      v1::Pose* start = request.mutable_robot()->mutable_start();
      start->set_x(p.x);
      start->set_y(p.y);
      start->set_theta(std::uniform_real_distribution<double>(0.0, 2 * M_PI)(rng));
    }
    return request;
  }

  absl::StatusOr<v1::PlanStats> Send(const v1::PlanRequest& request) const {
    const absl::Duration deadline = absl::Milliseconds(flags_.deadline);
    if (!flags_.full_replies) return remote_->PlanStatsOnly(request, deadline);
    absl::StatusOr<v1::PlanResponse> whole = remote_->Plan(request, deadline);
    return whole.ok() ? absl::StatusOr<v1::PlanStats>(whole->stats()) : whole.status();
  }

  void Tally(const absl::StatusOr<v1::PlanStats>& reply, double ms) {
    absl::MutexLock lock(&mu_);
    ++report_.requests;
    ++report_.codes[absl::StatusCodeToString(reply.status().code())];
    report_.latencies_ms.push_back(ms);
    if (reply.ok()) {
      ++report_.ok;
      report_.cut_short += reply->tour_cut_short();
      ++report_.plan_sources[SourceName(reply->plan_source())];
      report_.estimated_duration_sum_s += reply->estimated_duration_s();
    }
    if (ms > static_cast<double>(flags_.deadline)) ++report_.late;
  }

  void Work(int t) {
    std::mt19937_64 rng(static_cast<uint64_t>(flags_.seed.value_or(1)) * 1000003u + t);
    std::discrete_distribution<size_t> pick(weights_.begin(), weights_.end());
    const absl::Time start = absl::Now();
    for (int64_t k = 0; absl::Now() < end_; ++k) {
      if (!TakeTicket()) break;
      if (flags_.rate) {
        const absl::Time due =
            start + absl::Seconds(static_cast<double>(k * flags_.threads + t) / *flags_.rate);
        if (due >= end_) break;
        absl::SleepFor(due - absl::Now());
      }
      const v1::PlanRequest request = RequestFor(pick(rng), rng);
      const absl::Time sent = absl::Now();
      const absl::StatusOr<v1::PlanStats> reply = Send(request);
      Tally(reply, absl::ToDoubleMilliseconds(absl::Now() - sent));
      // Back off briefly after a refusal so an overloaded server is probed,
      // not hammered.
      if (absl::IsResourceExhausted(reply.status())) {
        absl::SleepFor(absl::Milliseconds(flags_.backoff_ms.value_or(10)));
      }
    }
  }

  const LoadFlags& flags_;
  const PreparedMaps& maps_;
  RemotePlanner* const remote_;
  std::vector<double> weights_;  // map k's share of the requests
  absl::Time end_;               // set before the workers start
  absl::Mutex mu_;
  int64_t issued_ = 0;  // guarded by mu_
  LoadReport report_;   // guarded by mu_ while the workers run
};

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(
      ParsedArgs a,
      ParseArgs(args,
                WithConnectionFlags({"server", "map", "maps", "concurrency", "duration",
                                     "deadline-ms", "resolution", "tool-width", "time-limit",
                                     "tour", "backoff-ms", "zipf", "seed", "requests", "rate"}),
                {"inline", "random-start", "full-replies"}));
  ASSIGN_OR_RETURN(const LoadFlags flags, ParseLoadFlags(a));
  std::vector<std::string> files;
  if (a.Get("map")) {
    files.push_back(*a.Get("map"));
  } else {
    ASSIGN_OR_RETURN(files, MapFiles(*a.Get("maps")));
  }
  ASSIGN_OR_RETURN(Connection connection, ConnectionFromArgs(a, flags.server));
  std::unique_ptr<RemotePlanner> remote = RemotePlanner::Connect(connection);
  ASSIGN_OR_RETURN(const PreparedMaps maps, PrepareMaps(flags, files, remote.get()));
  const LoadReport report = LoadRun(flags, maps, remote.get()).Run();
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
  std::string sources_json;
  for (const auto& [source, count] : plan_sources) {
    absl::StrAppend(&sources_json, sources_json.empty() ? "" : ", ", "\"", source, "\": ", count);
  }
  std::string ids_json;
  if (!map_ids.empty())
    ids_json = absl::StrCat(", \"map_ids\": [\"", absl::StrJoin(map_ids, "\", \""), "\"]");
  return absl::StrFormat(
      "{\"requests\": %d, \"ok\": %d, \"codes\": {%s}, \"p50_ms\": %.2f, \"p95_ms\": %.2f, "
      "\"p99_ms\": %.2f, \"max_ms\": %.2f, \"late\": %d, \"cut_short\": %d, "
      "\"concurrency\": %d, \"maps\": %d, \"deadline_ms\": %d, \"duration_s\": %.2f, "
      "\"throughput_rps\": %.2f, \"random_start\": %s, \"plan_sources\": {%s}, "
      "\"mean_estimated_duration_s\": %.3f%s}",
      requests, ok, codes_json, Percentile(sorted, 0.50), Percentile(sorted, 0.95),
      Percentile(sorted, 0.99), sorted.empty() ? 0.0 : sorted.back(), late, cut_short, concurrency,
      maps, deadline_ms, duration_s, duration_s > 0 ? requests / duration_s : 0.0,
      random_start ? "true" : "false", sources_json, ok > 0 ? estimated_duration_sum_s / ok : 0.0,
      ids_json);
}

int RunLoadCommand(const std::vector<std::string>& args) {
  return RunSubcommand("load", kUsage, args, &Run);
}

}  // namespace covplan
