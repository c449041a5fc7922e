// Memetic search for the GTSP, in the style of Gutin & Karapetyan's memetic
// algorithm ("A memetic algorithm for the generalized traveling salesman
// problem", Natural Computing 2010): a population of distinct locally optimal
// tours evolves by a fragment crossover, a rare segment-reversal mutation and
// the LocalSearch of gtsp_local.h (relocate, 2-opt, exact vertex
// re-selection) applied to every child.
//
// Used when the solver has a deadline to fill (thorough effort): on GTSPLIB it
// reaches a given gap in a fraction of the time of the LNS trials, because
// recombining local optima keeps the good arcs they share.
//
//   MemeticSearch ms(problem, params, SeedFor(seed, thread));  // params.time_budget_end set
//   TrialOutcome out = ms.Run(&warm_or_nullptr, stop, on_best);
//
// Thread-safety: one instance per thread; many may share one const Problem.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_GTSP_MEMETIC_H_
#define COVPLAN_PLANNER_TOUR_GTSP_GTSP_MEMETIC_H_

#include <functional>
#include <vector>

#include "planner/common/stop_token.h"
#include "planner/tour/gtsp/gtsp_local.h"
#include "planner/tour/gtsp/gtsp_problem.h"
#include "planner/tour/gtsp/gtsp_search.h"
#include "planner/tour/gtsp/rng.h"

namespace covplan::gtsp_internal {

class MemeticSearch {
 public:
  // Tours in the population, children per generation.
  static constexpr int kPopulation = 30;
  // Generations without a new best before all but the two best tours are
  // replaced by fresh random ones.
  static constexpr int kStaleGenerations = 8;

  // `params.time_budget_end` ends the run between children, and the
  // StopToken also inside a child's local search (SolveGtsp sets both to
  // the deadline); the other fields are used only to build the
  // random-insertion tours that seed the population.
  MemeticSearch(const Problem& p, const SearchParams& params, uint64_t seed);

  // Evolves a population that contains `start` (if given) until the time
  // budget ends or `stop` fires; `iterations` in the outcome counts children.
  // `on_best` is called whenever the best tour improves.
  TrialOutcome Run(const SearchTour* start, const StopToken& stop,
                   const std::function<void(const SearchTour&)>& on_best);

  // Child of `a` and `b`: a random fragment of `a` (its set order and
  // vertices), then every other set in the order, and with the vertex, of `b`
  // starting after the fragment's last set. Exposed for tests.
  void Crossover(const SearchTour& a, const SearchTour& b, SearchTour& child);

 private:
  // Appends a locally optimised random-insertion tour.
  void AddRandomTour(std::vector<SearchTour>& pop, const StopToken& stop);
  // Sorts by cost, drops tours whose cost equals a better one's, keeps kPopulation.
  void Select(std::vector<SearchTour>& pop);
  int Tournament(int size);
  void Mutate(SearchTour& t);

  const Problem& p_;
  SearchParams params_;
  Rng rng_;
  LocalSearch local_;
  LnsTrial builder_;  // random-insertion construction only
  ClusterOptScratch cluster_scratch_;
  std::vector<char> taken_;
};

}  // namespace covplan::gtsp_internal

#endif  // COVPLAN_PLANNER_TOUR_GTSP_GTSP_MEMETIC_H_
