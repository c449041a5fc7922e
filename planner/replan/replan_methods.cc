#include "planner/replan/replan_methods.h"

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/push_relabel_partitioner.h"
#include "planner/replan/tour_replan.h"

namespace covplan::replan_internal {
namespace {

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

// Out of time (or cancelled): the method gives up and the greedy detour answers.
bool RanOutOfTime(const absl::Status& status) {
  return absl::IsDeadlineExceeded(status) || absl::IsCancelled(status);
}

}  // namespace

void UseGreedyDetour(const Remainder& rest, const Walk& whole, ReplanResult* out) {
  ReplanStats& st = out->stats;
  out->plan.path = whole.path;
  out->plan.sweeps = whole.sweeps;
  // A walk that ended inside a blocked stretch (the old end cut off) still
  // drives to the (moved) end; the route is short and needs no deadline.
  AppendRoute(*rest.drive, whole.end, rest.end, StopToken(), &out->plan.path).IgnoreError();
  st.greedy_detours.clear();
  for (int k = 0; k < whole.encounters; ++k) st.greedy_detours.push_back(k);
  st.replanned_encounter = -1;
  st.time_to_encounter_s = 0.0;
  st.rank_budget = -1;
  st.new_ranks = st.kept_ranks = st.kept_path_pieces = 0;
  st.kept_path_m = 0.0;
  st.method = ReplanMethodName(ReplanMethod::kGreedyDetour);
  out->plan.termination = Termination::Converged("greedy detour: no search");
  out->plan.detail = rest.old->plan.detail;  // whole coverage legs keep their rank tags
}

absl::StatusOr<bool> ReplanFull(const Remainder& rest, const ReplanOptions& options,
                                const StopToken& stop, ReplanResult* out) {
  ReplanStats& st = out->stats;
  st.method = ReplanMethodName(ReplanMethod::kFull);
  const Grid w = rest.old->area->drive->WithFreeFlags(rest.to_cover);
  const absl::Time t0 = absl::Now();
  std::vector<Rank> ranks;
  if (st.remaining_cells > 0) {
    absl::StatusOr<RankPartition> p = PushRelabelPartitioner().Partition(w, stop);
    if (!p.ok() && !RanOutOfTime(p.status())) return p.status();
    if (p.ok()) ranks = std::move(p->ranks);
  }
  st.rank_replan_ms = MsSince(t0);
  st.new_ranks = static_cast<int64_t>(ranks.size());
  Walk at_robot;
  at_robot.path = {{rest.at.at.x, rest.at.at.y, rest.at.heading, SegmentKind::kStart, -1}};
  at_robot.end = rest.at.at;
  at_robot.end_heading = rest.at.heading;
  at_robot.end_leg = static_cast<int>(rest.legs.size());  // no old sections kept
  out->plan.path = at_robot.path;
  out->plan.sweeps.clear();
  auto detail = std::make_shared<OarpDetail>();
  detail->ranks = ranks;
  out->plan.detail = detail;
  if (stop.ShouldStop() || (ranks.empty() && st.remaining_cells > 0)) return false;
  const std::vector<bool> all_new(ranks.size(), true);
  return TourReplan(rest, at_robot, ranks, all_new, options, stop, 30.0, out);
}

absl::StatusOr<bool> ReplanRanks(const Remainder& rest, const RankAttempt& attempt,
                                 const ReplanOptions& options, ReplanResult* out) {
  ReplanStats& st = out->stats;
  std::vector<Rank> ranks;
  std::vector<bool> is_new;
  if (attempt.input.cells->CountFree() > 0) {
    absl::StatusOr<RankReplanResult> rr = RankReplan(attempt.input, attempt.method, attempt.stop);
    if (!rr.ok()) {
      // No partition within the budget, or no time: this encounter is detoured.
      if (absl::IsFailedPrecondition(rr.status()) || RanOutOfTime(rr.status())) return false;
      return rr.status();
    }
    ranks = std::move(rr->ranks);
    is_new = std::move(rr->is_new);
    st.new_ranks = rr->num_new;
    st.rank_lp_integral = rr->relaxation_integral;
  }
  st.rank_replan_ms = MsSince(attempt.start);
  st.kept_ranks = static_cast<int64_t>(ranks.size()) - st.new_ranks;
  st.rank_budget = attempt.input.budget;
  const Walk& prefix = *attempt.prefix;
  out->plan.path = prefix.path;
  for (Waypoint& wp : out->plan.path) wp.rank = -1;  // the tour's tags index the new partition
  out->plan.sweeps = prefix.sweeps;
  auto detail = std::make_shared<OarpDetail>();
  detail->ranks = ranks;
  out->plan.detail = detail;
  st.kept_path_pieces = 0;
  st.kept_path_m = 0;
  const double tour_budget =
      std::max(1e-3, attempt.budget_s - absl::ToDoubleSeconds(absl::Now() - attempt.start));
  return TourReplan(rest, prefix, ranks, is_new, options, attempt.stop, tour_budget, out);
}

}  // namespace covplan::replan_internal
