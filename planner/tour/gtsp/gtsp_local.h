// Local re-optimisation of a full GTSP tour, used by the LNS on promising
// candidates:
//  - relocate: move one set to another position, re-picking its vertex given
//    the new neighbours (or re-pick it in place);
//  - 2-opt: reverse a segment of the set order (asymmetric costs are priced
//    exactly with prefix sums of both walking directions);
//  - cluster optimisation: exact re-selection of every set's vertex for the
//    fixed set order (shortest cycle through the layered graph).
// Relocate and 2-opt take candidate positions from the near-set lists and use
// a work queue of "dirty" sets (don't-look bits), so re-optimising a tour that
// differs from a local optimum in a few places costs little.
//
//   LocalSearch ls(problem);
//   ls.Run(tour, &changed_sets, stop);   // nullptr: every set is dirty
//
// Thread-safety: one instance per thread; it owns scratch buffers.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_GTSP_LOCAL_H_
#define COVPLAN_PLANNER_TOUR_GTSP_GTSP_LOCAL_H_

#include <vector>

#include "planner/common/stop_token.h"
#include "planner/tour/gtsp/gtsp_problem.h"

namespace covplan::gtsp_internal {

class LocalSearch {
 public:
  explicit LocalSearch(const Problem& p);

  // Improves `t` until no move applies (or `stop`). `dirty`: the sets whose
  // surroundings changed since `t` was last locally optimal (nullptr: all).
  // Returns true if the tour improved.
  bool Run(SearchTour& t, const std::vector<int>* dirty, const StopToken& stop);

 private:
  static constexpr int kNeighbors = 16;

  void Activate(int set);
  void ActivateAround(const SearchTour& t, int index);
  bool TryRelocate(SearchTour& t, int set);
  bool TryTwoOpt(SearchTour& t, int set);
  void RebuildPrefix(const SearchTour& t);

  const Problem& p_;
  ClusterOptScratch cluster_scratch_;
  std::vector<char> active_;
  std::vector<int> queue_;
  std::vector<double> fwd_, bwd_;  // prefix path costs walking forwards / backwards
  bool prefix_valid_ = false;
  std::vector<int> before_;
};

}  // namespace covplan::gtsp_internal

#endif  // COVPLAN_PLANNER_TOUR_GTSP_GTSP_LOCAL_H_
