// Anytime solver for the Generalized Travelling Salesman Problem (GTSP):
// vertices are partitioned into sets; find a cycle visiting exactly one vertex
// of every set with minimum total (possibly asymmetric) cost.
//
// Large-neighbourhood search in the style of GLNS (Smith & Imeson 2017):
// several removal and insertion heuristics with adaptive weights, simulated-
// annealing acceptance, restarts/trials, and a local step that re-picks the
// vertex of each set. A thorough solve with a deadline instead evolves one
// population of local optima per thread (the memetic search of
// gtsp_memetic.h, after Gutin & Karapetyan 2010), then runs LNS trials from
// its best until the deadline (GtspSearch). Anytime: it always holds a valid
// tour and returns the best one found when the StopToken fires.
//
//   GtspInstance inst = ...;               // costs + sets
//   GtspOptions opt; opt.seed = 7;
//   opt.stop = StopToken::WithTimeout(absl::Seconds(1));
//   absl::StatusOr<GtspResult> r = SolveGtsp(inst, opt);
//
// Deterministic for a given (instance, seed, num_threads) when the run is not
// cut short by the deadline (i.e. when it stops on its own iteration limits);
// a thorough solve with a deadline is not, since it runs until the clock says.
// Thread-safety: SolveGtsp is reentrant; it may use opt.num_threads threads.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_GTSP_H_
#define COVPLAN_PLANNER_TOUR_GTSP_GTSP_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"

namespace covplan {

// Dense asymmetric cost matrix; cost(i, j) is the cost of the arc i -> j.
// Use kInfeasibleCost for arcs that must not be used.
struct GtspInstance {
  static constexpr double kInfeasibleCost = 1e15;
  int num_vertices = 0;
  std::vector<double> costs;           // num_vertices^2, row-major
  std::vector<std::vector<int>> sets;  // 0-based vertex ids; partition of vertices
  double cost(int i, int j) const { return costs[static_cast<size_t>(i) * num_vertices + j]; }

  // Checks shapes, that sets partition the vertices and are non-empty, and
  // that costs are finite and non-negative.
  absl::Status Validate() const;
};

enum class GtspEffort { kFast, kDefault, kThorough };

// The search that fills a deadline (thorough effort, a deadline, no trial
// limit); the other efforts always run LNS trials.
enum class GtspSearch {
  kHybrid,   // per thread: the memetic search, then LNS trials from its best
  kLns,      // the effort's LNS trials, the time spread over them
  kMemetic,  // per thread: the memetic search until the deadline
};

struct GtspOptions {
  uint64_t seed = 1;
  int num_threads = 1;  // without a deadline, the effort's trials run in
                        // whole rounds of this many; with one, each thread
                        // runs its own search (thread 0 the one-thread one)
  GtspEffort effort = GtspEffort::kDefault;
  GtspSearch search = GtspSearch::kHybrid;  // with a deadline to fill (see GtspSearch)
  int max_trials = 0;  // 0 = chosen by effort; kLocalStepOnly: no LNS trial; with a
                       // deadline, per thread (each thread runs its own chain)
  static constexpr int kLocalStepOnly = -1;  // the initial (or greedy) tour, locally optimised
  StopToken stop;                            // deadline / cancellation
  // Optional starting tour (one vertex per set, in visiting order) to improve.
  std::vector<int> initial_tour;
  // Called (from solver threads, serialized) whenever the best tour improves.
  std::function<void(double cost, double elapsed_s)> on_improvement;

  absl::Status Validate() const;
};

struct GtspResult {
  std::vector<int> tour;       // one vertex per set, visiting order (cycle)
  double cost = 0.0;           // sum of arc costs including the closing arc
  bool stopped_early = false;  // the StopToken cut the search short
  int64_t iterations = 0;      // LNS iterations, plus children evolved (thorough with a deadline)
  int trials_completed = 0;    // LNS trials that ended before the StopToken fired, over all
                               // threads (thorough with a deadline: the hybrid's, or num_threads
                               // when m = 2 and the memetic search's local step is exact)
  double elapsed_s = 0.0;
  double time_to_best_s = 0.0;
};

// Cost of a cycle through `tour` (closing arc included).
double TourCost(const GtspInstance& instance, const std::vector<int>& tour);
// Checks one vertex per set, ids in range.
absl::Status ValidateTour(const GtspInstance& instance, const std::vector<int>& tour);

// InvalidArgument for a malformed instance/options. If the StopToken fires
// before a first tour exists, a (greedy) valid tour is still returned.
absl::StatusOr<GtspResult> SolveGtsp(const GtspInstance& instance, const GtspOptions& options);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_GTSP_GTSP_H_
