// Rank tours on large maps without any dense matrix: the sparse counterpart
// of RankTourCost + GtspOrderer + BuildPath.
//
// The tour is a sequence of rank endpoints: start, (entry, exit) of each
// rank, end. A transition x -> y costs what RankTourCost charges: the robot's
// time (path_timing.h) along the any-angle path, with the turn from x's rank
// heading and onto y's. Paths of candidate pairs come from the
// EndpointGraph; others are searched on demand (AnyAngleSearch::RunTo) and
// their costs cached for the request; a completed search also caches the
// exact cost to every other endpoint it settled on the way (their paths are
// final). Moves are priced first with a lower
// bound (straight-line time of the Euclidean distance plus the turns onto
// and off the straight line), then with a capped probe search, and only then
// exactly, so full searches run only for moves that could still improve.
// Endpoint-to-endpoint costs are symmetric, so reversing a run of ranks (all
// directions flipped) keeps its inner cost.
//
// Search: nearest neighbour over the candidate lists (with a bucket-grid
// fallback to the nearest unvisited endpoints when all candidates are
// visited), then 2-opt and Or-opt (1-3 ranks, either direction) restricted
// to candidate lists, driven by a work queue, then iterated local search
// with local double-bridge kicks and undo: one construction, then per
// thread a descent (odd threads with the work queue reversed), then the
// kick phase, in which every thread (its own seed) kicks one shared
// incumbent tour: a thread publishes a tour that beats it and takes a newer
// one before its next kick. The threads share the cost cache; the returned
// tour is audited (order, positions, links, cost).
// A warm start replaces the construction by a remembered tour.
// Three units: the cost oracle (sparse_cost_oracle.h: bounds, probes, exact
// costs and their cache), the local search (sparse_local_search.h:
// construction, 2-opt/Or-opt, kicks, the shared incumbent) and this driver
// (poses, threads, the final paths).
// Only the final tour's transitions become paths (in parallel); plan
// durations come from those paths.
//
//   ASSIGN_OR_RETURN(SparseTour tour, PlanSparseRankTour(drive, ranks, *graph, robot, opts, stop));
//
// Thread-safety: PlanSparseRankTour is reentrant; the graph is read-only.
#ifndef COVPLAN_PLANNER_TOUR_SPARSE_TOUR_H_
#define COVPLAN_PLANNER_TOUR_SPARSE_TOUR_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/endpoint_graph.h"
#include "planner/tour/robot_model.h"

namespace covplan {

// Fixed bytes of each search thread beyond its grid-sized search scratch
// (the memo of lower bounds).
inline constexpr int64_t kSparseTourBytesPerThread = int64_t{16} << 16;

struct SparseTourOptions {
  double time_limit_s = 1.0;  // search budget (construction and paths excluded)
  uint64_t seed = 1;
  int num_threads = 1;
  bool local_search = true;  // false: nearest-neighbour tour only
  bool until_limit = false;  // true: keep kicking until the budget is spent
  // Kicks without improvement, summed over all threads, after which the
  // kick phase counts as converged: threads * max(min_kicks, kicks_per_rank
  // * ranks).
  int64_t min_kicks = 500;
  double kicks_per_rank = 1.0;
  int64_t max_cached_pairs = 4'000'000;  // on-demand exact lengths kept
  // A remembered tour to start from instead of the nearest-neighbour
  // construction: rank-tour vertices as SparseTour::vertices, one per rank.
  // It is taken as a cycle and cut where it suits this start and end best
  // (either direction), then descended. Without warm_kicks no kicks follow
  // (a new start pose's warm start); with them the kick phase runs as cold.
  // A tour that does not visit every rank once is ignored (cold search).
  std::vector<int> warm_vertices;
  bool warm_kicks = true;
};

struct SparseTour {
  std::vector<int> vertices;    // rank-tour vertices 2k + d, as RankTourCost
  std::vector<Waypoint> path;   // start, transitions, coverage, return
  double surrogate_cost = 0.0;  // the search's objective (seconds), for tests and logs
  bool stopped_early = false;
  Termination termination;
  int64_t exact_searches = 0;  // on-demand OctileSearch runs
  bool warm_started = false;   // began from options.warm_vertices
};

// InvalidArgument if the start/end pose cannot join the grid or a rank is
// not reachable from the start; DeadlineExceeded if `stop` fires before a
// complete tour exists.
absl::StatusOr<SparseTour> PlanSparseRankTour(const Grid& drive, const std::vector<Rank>& ranks,
                                              const EndpointGraph& graph, const RobotModel& robot,
                                              const SparseTourOptions& options,
                                              const StopToken& stop);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_SPARSE_TOUR_H_
