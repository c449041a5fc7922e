// TOUR-REPLAN (thesis §4.5; internal to planner/replan): the tour that
// finishes a replan. From where a walk over the old path stopped, it orders
// the ranks of the new partition with the anytime GTSP (planner/tour) and
// ends at the remainder's end pose. The maximal unchanged sections of the old
// path after the walk, whose coverage segments are all kept ranks, enter the
// tour whole, so that what the robot was going to drive anyway stays as it was.
//
//   ASSIGN_OR_RETURN(bool toured, TourReplan(rest, prefix, ranks, is_new, options,
//                                            stop, budget_s, &out));
//   if (!toured) { /* out of time: the greedy detour answers */ }
//
// Thread-safety: reentrant (the tour search runs on options.num_threads
// threads of its own).
#ifndef COVPLAN_PLANNER_REPLAN_TOUR_REPLAN_H_
#define COVPLAN_PLANNER_REPLAN_TOUR_REPLAN_H_

#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/partition/rank.h"
#include "planner/replan/remainder.h"
#include "planner/replan/replan_walk.h"
#include "planner/replan/replanner.h"

namespace covplan::replan_internal {

// Appends to out->plan (whose path ends where `walk` ends) the tour over
// `ranks` (is_new: per rank, not one of the old plan's), and sets the plan's
// termination, adds the kept sections of the old path to the stats'
// kept_path_pieces and kept_path_m, and sets their transitions_ms and tour_ms. The tour search
// stops at the earlier of `stop`, `tour_budget_s` and options.tour_time_limit_s. False when the
// time ran out first.
absl::StatusOr<bool> TourReplan(const Remainder& rest, const Walk& walk,
                                const std::vector<Rank>& ranks, const std::vector<bool>& is_new,
                                const ReplanOptions& options, const StopToken& stop,
                                double tour_budget_s, ReplanResult* out);

}  // namespace covplan::replan_internal

#endif  // COVPLAN_PLANNER_REPLAN_TOUR_REPLAN_H_
