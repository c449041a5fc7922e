// The replanning methods (internal to planner/replan). Each fills a
// ReplanResult from the Remainder; Replan (replanner.cc) picks one, gives it
// its time and answers with the greedy detour when it returns false:
// - UseGreedyDetour: the greedy walk over all of the remaining path, with a
//   detour around every encounter (no search; always succeeds).
// - ReplanFull: OARP-Original, a new partition of everything left
//   (push-relabel) toured from the robot; the robot waits for it.
// - ReplanRanks: one step of Algorithm 1, at one encounter of the greedy walk:
//   RANK-REPLAN (ILP-1 or ILP-2 in GLPK, rank_replan.h) of what the walk
//   leaves, within the rank budget, then TOUR-REPLAN from the encounter.
//
//   ASSIGN_OR_RETURN(bool done, ReplanFull(rest, options, stop, &out));
//   if (!done) UseGreedyDetour(rest, whole, &out);
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_REPLAN_REPLAN_METHODS_H_
#define COVPLAN_PLANNER_REPLAN_REPLAN_METHODS_H_

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "planner/replan/rank_replan.h"
#include "planner/replan/remainder.h"
#include "planner/replan/replan_walk.h"
#include "planner/replan/replanner.h"

namespace covplan::replan_internal {

// Sets out->plan to `whole` (the greedy walk over all of rest.legs) driven on
// to rest.end, with the old plan's rank tags, and the stats to say so.
void UseGreedyDetour(const Remainder& rest, const Walk& whole, ReplanResult* out);

// A new partition of everything left, toured from the robot within `stop`.
// False when `stop` ended it first; errors of the partitioner or the tour
// other than running out of time are passed on.
absl::StatusOr<bool> ReplanFull(const Remainder& rest, const ReplanOptions& options,
                                const StopToken& stop, ReplanResult* out);

// One attempt of Algorithm 1 at an encounter.
struct RankAttempt {
  const Walk* prefix = nullptr;  // the greedy walk up to (not into) the encounter
  // W (what the prefix leaves to cover), the old ranks and the budget m̄.
  RankReplanInput input;
  RankReplanMethod method = RankReplanMethod::kIlp2;
  StopToken stop;         // the encounter's deadline
  double budget_s = 0.0;  // seconds until the robot reaches the encounter, less the margin
  absl::Time start;       // when the attempt started (its time counts from here)
};

// RANK-REPLAN of attempt.input, then TOUR-REPLAN from the end of the prefix:
// out->plan is the prefix followed by the tour, tagged with the new
// partition; the stats get the rank figures. False when no partition fits
// the budget or the time ran out (the caller moves on to the next
// encounter); other errors are passed on.
absl::StatusOr<bool> ReplanRanks(const Remainder& rest, const RankAttempt& attempt,
                                 const ReplanOptions& options, ReplanResult* out);

}  // namespace covplan::replan_internal

#endif  // COVPLAN_PLANNER_REPLAN_REPLAN_METHODS_H_
