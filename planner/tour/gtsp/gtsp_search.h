// One trial of the GLNS-style large-neighbourhood search on a Problem.
//
// Each iteration removes k sets from the current tour (random, worst,
// segment or distance removal), re-inserts one vertex per removed set (the
// best vertex at the best position; cheapest-, farthest- or random-order
// insertion, optionally with noise), locally re-optimises promising tours
// around the re-inserted sets (LocalSearch: relocate with vertex re-pick,
// asymmetric 2-opt, exact vertex re-selection for the set order) and accepts
// by a simulated-annealing rule.
// Heuristics are drawn with adaptive weights rewarded by success.
//
//   LnsTrial trial(problem, params, SeedFor(seed, index));
//   TrialOutcome out = trial.Run(warm_start_or_nullptr, stop, on_best);
//
// Thread-safety: an LnsTrial is used by one thread; many trials may share the
// same const Problem.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_GTSP_SEARCH_H_
#define COVPLAN_PLANNER_TOUR_GTSP_GTSP_SEARCH_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "planner/tour/gtsp/gtsp_local.h"
#include "planner/tour/gtsp/gtsp_problem.h"
#include "planner/tour/gtsp/rng.h"

namespace covplan::gtsp_internal {

struct SearchParams {
  int64_t max_iterations = 10000;  // per trial
  // End the trial after this many iterations without a new trial best (only
  // counted in the second half of the annealing schedule).
  int64_t stall_iterations = 5000;
  double max_removal_fraction = 0.25;
  int max_removals_cap = 60;
  // Simulated annealing: a tour `accept_start` (relative) worse than the
  // current one is accepted with probability 1/2 at the start of the trial,
  // `accept_end` worse at the end; geometric in between.
  double accept_start = 0.03;
  double accept_end = 0.0003;
  double warm_start_factor = 0.3;  // accept_start multiplier for warm starts
  // Candidates within this relative distance of the trial best are always
  // locally optimised; others with probability `local_probability`.
  double local_window = 0.02;
  double local_probability = 0.1;
  // Insertion positions tried for a set: the arcs around its this-many
  // nearest sets in the tour (0 = every arc of the tour, as in GLNS).
  int insertion_neighbors = 12;
  // If finite, the annealing schedule also advances with wall-clock time so
  // that the trial cools down by this time (used only with a deadline).
  absl::Time time_budget_end = absl::InfiniteFuture();
};

struct TrialOutcome {
  SearchTour best;
  int64_t iterations = 0;
  bool stopped = false;  // the StopToken ended the trial
};

// Best insertion of one set: vertex `v` after vertex `after` (-1: empty tour).
struct Insertion {
  double cost = 0.0;
  int v = -1;
  int after = -1;
};

class LnsTrial {
 public:
  LnsTrial(const Problem& p, const SearchParams& params, uint64_t seed);

  // Runs one trial from `start` (nullptr: a random-insertion tour).
  // `on_best(tour)` is called whenever the trial best improves.
  TrialOutcome Run(const SearchTour* start, const StopToken& stop,
                   const std::function<void(const SearchTour&)>& on_best);

  // Builds a full tour by inserting all sets into an empty tour; mode as in
  // InsertSets. Exposed for the driver's greedy start.
  void Construct(SearchTour& t, int mode);

  // Full local re-optimisation (see LocalSearch). True if improved.
  bool LocalOptimize(SearchTour& t, const StopToken& stop) { return local_.Run(t, nullptr, stop); }

 private:
  enum InsertMode { kNearest = 0, kFarthest = 1, kRandomOrder = 2 };
  static constexpr int kNumRemovals = 4;
  static constexpr int kNumInsertions = 9;  // 3 modes x 3 noise levels

  void Remove(SearchTour& t, int heuristic, int k);
  void InsertSets(SearchTour& t, int mode, double noise);
  void Evaluate(const SearchTour& t, int set, double noise, Insertion& out);
  void EvaluateEdge(int a, int b, int set, double noise, Insertion& io);
  int Roulette(const double* weights, int count);

  const Problem& p_;
  SearchParams params_;
  Rng rng_;
  LocalSearch local_;
  // Scratch buffers reused by every iteration.
  std::vector<int> removed_;
  std::vector<int> touched_;  // sets re-inserted by the current iteration
  std::vector<char> drop_;
  std::vector<Insertion> cache_;
  std::vector<int> idx_;
  std::vector<double> gain_;
  std::vector<int> link_prev_, link_next_;
  std::vector<int> order_;
  double removal_weight_[kNumRemovals];
  double insertion_weight_[kNumInsertions];
  double removal_score_[kNumRemovals];
  double insertion_score_[kNumInsertions];
  int removal_uses_[kNumRemovals];
  int insertion_uses_[kNumInsertions];
};

}  // namespace covplan::gtsp_internal

#endif  // COVPLAN_PLANNER_TOUR_GTSP_GTSP_SEARCH_H_
