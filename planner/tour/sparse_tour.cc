#include "planner/tour/sparse_tour.h"

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>
#include <thread>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/element_tour.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/gtsp/rng.h"
#include "planner/tour/rank_tour.h"
#include "planner/tour/sparse_cost_oracle.h"
#include "planner/tour/sparse_local_search.h"

namespace covplan {
namespace {

using sparse_internal::AuditTour;
using sparse_internal::Incumbent;
using sparse_internal::kCostEps;
using sparse_internal::SearchRun;
using sparse_internal::SparseCostOracle;

// The tour's poses and where they join the grid.
struct Poses {
  Pose2 start, end;
  CellIndex start_cell, end_cell;
};

// InvalidArgument unless both poses join the grid in the component of
// every rank endpoint.
absl::StatusOr<Poses> JoinPoses(const Grid& drive, const std::vector<Rank>& ranks,
                                const EndpointGraph& graph, const RobotModel& robot) {
  Poses p;
  p.start = RankTourStart(drive, ranks, robot);
  p.end = robot.end.value_or(p.start);
  ASSIGN_OR_RETURN(p.start_cell, JoinCell(drive, p.start, "start"));
  ASSIGN_OR_RETURN(p.end_cell, JoinCell(drive, p.end, "end"));
  const int n = static_cast<int>(ranks.size());
  const int start_comp = graph.component(p.start_cell);
  for (int e = 0; e < 2 * n; ++e) {
    if (graph.endpoint_component(e) != start_comp) {
      return absl::InvalidArgumentError(
          absl::StrFormat("rank %d cannot be reached from the start pose (%.3f, %.3f)", e / 2,
                          p.start.x, p.start.y));
    }
  }
  if (graph.component(p.end_cell) != start_comp) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the end pose (%.3f, %.3f) cannot be reached from the start pose", p.end.x, p.end.y));
  }
  return p;
}

// The best tour of all search threads, as nodes [S, entry, exit, ..., E].
struct SearchResult {
  std::vector<int> tour;
  double cost = std::numeric_limits<double>::infinity();
  bool converged = true;  // every thread's search ended before the budget
  bool warm = false;      // began from options.warm_vertices
  bool kicks = false;     // the kick phase ran
};

// One construction (deterministic: repeating it per thread would only
// duplicate work), then per thread a descent from it, and the kick phase:
// with one thread a plain iterated local search, with more each thread
// kicks the shared incumbent with its own seed. The threads share the cost
// cache.
absl::StatusOr<SearchResult> SearchTour(SparseCostOracle* oracle, const SparseTourOptions& options,
                                        const StopToken& stop) {
  const int n = oracle->n();
  const absl::Time began = absl::Now();
  const StopToken budget = stop.WithEarlierDeadline(began + absl::Seconds(options.time_limit_s));
  const int threads = options.local_search ? std::max(1, options.num_threads) : 1;
  // Kicks without gain, counted over all threads (they kick one shared
  // incumbent): one thread's count per thread that has a core. With one
  // thread's count in all, two threads converged in 0.83 of one thread's
  // wall time but on tours 0.5 % longer (lab_a at 0.3 m); with this, as
  // long as one thread's in the mean, in 0.93 of its wall time
  // (docs/benchmarks.md §14). Threads beyond the cores would only stretch
  // the phase.
  const int64_t cores = std::max(1u, std::thread::hardware_concurrency());
  const int64_t converge_after =
      std::min<int64_t>(threads, cores) *
      std::max<int64_t>(options.min_kicks, static_cast<int64_t>(options.kicks_per_rank * n));
  Incumbent incumbent;
  struct Outcome {
    std::vector<int> tour;
    double cost = std::numeric_limits<double>::infinity();
    bool converged = true;
    absl::Status audit;
  };
  std::vector<Outcome> outcomes(threads);
  std::vector<std::unique_ptr<SearchRun>> runs;
  for (int t = 0; t < threads; ++t) {
    runs.push_back(std::make_unique<SearchRun>(oracle, gtsp_internal::SeedFor(options.seed, t)));
  }
  SearchResult result;
  result.warm = !options.warm_vertices.empty() && runs[0]->ConstructFrom(options.warm_vertices);
  if (!result.warm) RETURN_IF_ERROR(runs[0]->Construct(stop));
  const bool kicks = options.local_search && (!result.warm || options.warm_kicks);
  result.kicks = kicks;
  for (int t = 1; t < threads; ++t) runs[t]->CopyTour(*runs[0]);
  auto run = [&](int index) {
    SearchRun& r = *runs[index];
    Outcome& out = outcomes[index];
    if (options.local_search) {
      // Every thread descends from the shared start, odd threads with the
      // work queue reversed (another local optimum), while the others' exact
      // costs land in the shared cache.
      r.PushAll(/*reversed=*/index % 2 == 1);
      r.LocalSearch(budget);
    }
    if (kicks) {
      Incumbent* shared = threads > 1 ? &incumbent : nullptr;
      // The better descent becomes the incumbent; a thread that finishes
      // its descent first kicks its own until the other's beats it, and
      // kicks without gain count again from the better one.
      if (shared != nullptr && r.Publish(shared)) shared->stale = 0;
      out.converged =
          !budget.ShouldStop() && r.Iterate(budget, converge_after, options.until_limit, shared);
    } else if (options.local_search) {
      out.converged = !budget.ShouldStop();  // the descent ran to its end
    }
    out.tour = r.tour();
    out.cost = r.cost();
    out.audit = r.Audit();
  };
  {
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(run, t);
    run(0);
    for (auto& t : pool) t.join();
  }
  for (const Outcome& o : outcomes) RETURN_IF_ERROR(o.audit);
  int best = -1;
  for (int t = 0; t < threads; ++t) {
    if (best < 0 || outcomes[t].cost < outcomes[best].cost - kCostEps) best = t;
  }
  // A thread's last tour may trail the incumbent (its last gain lost to a
  // better one published meanwhile).
  if (kicks && threads > 1 && incumbent.cost < outcomes[best].cost - kCostEps) {
    RETURN_IF_ERROR(
        AuditTour(n, incumbent.t, incumbent.pos, incumbent.mate, incumbent.lc, incumbent.cost));
    outcomes[best].tour = incumbent.t, outcomes[best].cost = incumbent.cost;
  }
  for (const Outcome& o : outcomes) result.converged = result.converged && o.converged;
  result.tour = std::move(outcomes[best].tour);
  result.cost = outcomes[best].cost;
  return result;
}

// The tour's n + 1 transitions as any-angle paths (cells), in parallel.
absl::StatusOr<std::vector<std::vector<CellIndex>>> MaterialiseLegs(const Grid& drive,
                                                                    const SparseCostOracle& oracle,
                                                                    const std::vector<int>& t,
                                                                    int num_threads,
                                                                    const StopToken& stop) {
  const int n = oracle.n();
  std::vector<std::vector<CellIndex>> legs(n + 1);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  auto materialise = [&] {
    AnyAngleSearch search(drive);
    for (int k = next++; k <= n && !failed; k = next++) {
      const CellIndex a = oracle.cell(t[2 * k]), b = oracle.cell(t[2 * k + 1]);
      if (a == b) {
        legs[k] = {a};
        continue;
      }
      if (!search.RunTo(a, b, stop)) {
        failed = true;
        return;
      }
      legs[k] = search.PathTo(b);
      if (legs[k].empty()) failed = true;
    }
  };
  {
    const int mthreads = std::max(1, std::min(num_threads, n + 1));
    std::vector<std::thread> pool;
    for (int i = 1; i < mthreads; ++i) pool.emplace_back(materialise);
    materialise();
    for (auto& th : pool) th.join();
  }
  if (failed) {
    if (stop.ShouldStop())
      return absl::DeadlineExceededError("stopped while computing the tour's transition paths");
    return absl::InternalError("a tour transition has no any-angle path");
  }
  return legs;
}

// The waypoints: start, each leg's transitions and its rank, the last leg
// to the end.
std::vector<Waypoint> WritePath(const Grid& drive, const std::vector<Rank>& ranks,
                                const SparseCostOracle& oracle, const std::vector<int>& t,
                                const std::vector<std::vector<CellIndex>>& legs,
                                const Poses& poses) {
  const int n = oracle.n();
  std::vector<Waypoint> path;
  TourPathWriter writer(poses.start, &path, /*sweeps=*/nullptr);
  std::vector<Point2> pts;
  for (int k = 0; k <= n; ++k) {
    // A leg starts where the robot is: the start pose, or the cell of the
    // previous rank's exit.
    pts.clear();
    if (k == 0) pts.push_back({poses.start.x, poses.start.y});
    for (const CellIndex& c : legs[k]) pts.push_back(drive.CellCenter(c));
    if (k == n) pts.push_back({poses.end.x, poses.end.y});
    writer.Transit(pts);
    if (k == n) break;
    const int v = t[2 * k + 1];
    writer.Cover(drive.CellCenter(oracle.cell(v ^ 1)), RankHeading(ranks[v / 2], v % 2 == 0),
                 v / 2);
  }
  return path;
}

Termination SparseTermination(const SearchResult& result, const SparseTourOptions& options,
                              const StopToken& stop) {
  if (result.converged) {
    return Termination::Converged(
        !options.local_search ? "nearest-neighbour tour (no search)"
        : result.kicks
            ? "sparse tour search converged"
            : "sparse warm start: the remembered tour, cut for this start, locally optimised");
  }
  if (stop.cancelled()) {
    return Termination::LimitReached(TerminationLimit::kCancelled,
                                     "sparse tour search cancelled; best tour kept");
  }
  if (stop.ShouldStop()) {
    return Termination::LimitReached(TerminationLimit::kDeadline,
                                     "sparse tour search stopped by the deadline");
  }
  return Termination::LimitReached(TerminationLimit::kTime,
                                   "sparse tour search used its whole time limit");
}

}  // namespace

absl::StatusOr<SparseTour> PlanSparseRankTour(const Grid& drive, const std::vector<Rank>& ranks,
                                              const EndpointGraph& graph, const RobotModel& robot,
                                              const SparseTourOptions& options,
                                              const StopToken& stop) {
  if (ranks.empty()) return absl::InvalidArgumentError("no ranks to order");
  if (graph.num_endpoints() != static_cast<int>(2 * ranks.size())) {
    return absl::InvalidArgumentError("endpoint graph does not match the ranks");
  }
  ASSIGN_OR_RETURN(const Poses poses, JoinPoses(drive, ranks, graph, robot));
  SparseCostOracle oracle(drive, ranks, graph, robot, options.max_cached_pairs);
  if (!oracle.Prepare(poses.start, poses.start_cell, poses.end, poses.end_cell, stop)) {
    return absl::DeadlineExceededError("stopped while routing from the start pose");
  }
  ASSIGN_OR_RETURN(SearchResult result, SearchTour(&oracle, options, stop));
  ASSIGN_OR_RETURN(const std::vector<std::vector<CellIndex>> legs,
                   MaterialiseLegs(drive, oracle, result.tour, options.num_threads, stop));
  SparseTour tour;
  tour.warm_started = result.warm;
  tour.surrogate_cost = result.cost;
  tour.exact_searches = oracle.searches();
  for (int k = 0; k < oracle.n(); ++k) tour.vertices.push_back(result.tour[2 * k + 1]);
  tour.path = WritePath(drive, ranks, oracle, result.tour, legs, poses);
  tour.stopped_early = !result.converged;
  tour.termination = SparseTermination(result, options, stop);
  return tour;
}

}  // namespace covplan
