#include "planner/replan/replanner.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/replan/rank_replan.h"
#include "planner/replan/remainder.h"
#include "planner/replan/replan_methods.h"
#include "planner/replan/replan_walk.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

using replan_internal::RankAttempt;
using replan_internal::Remainder;
using replan_internal::Walk;

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

// Drive time of a path under the robot model (the robot turns in place to
// each waypoint's heading, then drives straight): the same rule as the plan
// statistics.
double PathTime(const std::vector<Waypoint>& path, const RobotModel& robot) {
  return ComputePathStats(path, robot).estimated_duration_s;
}

// FailedPrecondition when `old` cannot be replanned with `method`.
absl::Status CheckReplannable(const RetainedPlan& old, ReplanMethod method) {
  if (old.area == nullptr || old.plan.grid == nullptr || old.area->drive == nullptr) {
    return absl::FailedPreconditionError("the plan has no coverage area to replan on");
  }
  // A battery plan (or a greedy replan of one, which keeps its station legs
  // but not its cycle table): only the greedy detour keeps the station legs.
  // The ILP methods and kFull re-tour the remainder without charge stops, and
  // the battery state at the robot is not known here to split it again.
  const bool battery_plan =
      !old.plan.cycles.empty() ||
      std::any_of(old.plan.path.begin(), old.plan.path.end(), [](const Waypoint& w) {
        return w.kind == SegmentKind::kToStation || w.kind == SegmentKind::kFromStation;
      });
  if (battery_plan && method != ReplanMethod::kGreedyDetour) {
    return absl::FailedPreconditionError(
        absl::StrFormat("a battery plan (charge cycles) can only be replanned with method "
                        "greedy_detour, got %s: the other "
                        "methods would drop its station legs; plan again with the battery",
                        ReplanMethodName(method)));
  }
  return absl::OkStatus();
}

// The integer program for W: as asked, or under kAuto ILP-1 while it stays
// small enough (it is exact but grows with the square of the run lengths).
RankReplanMethod ChooseRankMethod(const ReplanOptions& options, const Grid& w) {
  if (options.method == ReplanMethod::kIlp1) return RankReplanMethod::kIlp1;
  if (options.method == ReplanMethod::kIlp2) return RankReplanMethod::kIlp2;
  return Ilp1ColumnEstimate(w) <= options.ilp1_max_columns ? RankReplanMethod::kIlp1
                                                           : RankReplanMethod::kIlp2;
}

// Algorithm 1: the encounters of the greedy walk `whole` in path order, each
// with the time the robot needs to reach it (less the time already spent
// since `start`) as its budget, and the rank budget the estimator allows in
// it; an encounter with too little time is detoured greedily. True when an
// attempt planned; the estimator learns from every attempt that did.
absl::StatusOr<bool> RunAlgorithm1(const Remainder& rest, const Walk& whole,
                                   const ReplanOptions& options, const StopToken& call_stop,
                                   absl::Time start, ReplanEstimator* estimator,
                                   ReplanResult* out) {
  ReplanStats& st = out->stats;
  const Grid& old_drive = *rest.old->area->drive;
  for (int k = 0; k < whole.encounters && !call_stop.ShouldStop(); ++k) {
    const Walk prefix = whole.Prefix(k, *rest.drive);
    // Per-attempt figures start afresh (a failed attempt leaves none behind).
    st.new_ranks = st.kept_ranks = st.kept_path_pieces = 0;
    st.kept_path_m = st.rank_replan_ms = st.transitions_ms = st.tour_ms = 0.0;
    st.rank_lp_integral = true;
    const double tau = PathTime(prefix.path, rest.robot);
    RankAttempt attempt;
    attempt.prefix = &prefix;
    attempt.budget_s = tau - options.safety_margin_s - absl::ToDoubleSeconds(absl::Now() - start);
    attempt.stop =
        call_stop.WithEarlierDeadline(absl::Now() + absl::Seconds(std::max(0.0, attempt.budget_s)));
    // Without an estimator the budget is unlimited (the time limit still holds).
    const int64_t m_bar = estimator != nullptr ? estimator->Budget(0.7 * attempt.budget_s)
                                               : RankReplanInput::kUnlimited;
    if (attempt.budget_s <= 0 || (estimator != nullptr && m_bar < 0) || attempt.stop.ShouldStop()) {
      st.greedy_detours.push_back(k);
      continue;
    }
    std::vector<uint8_t> wk = rest.to_cover;
    for (size_t i = 0; i < wk.size(); ++i) wk[i] = wk[i] && !prefix.swept[i];
    const Grid w = old_drive.WithFreeFlags(wk);
    attempt.input.cells = &w;
    if (rest.old_oarp != nullptr) attempt.input.old_ranks = rest.old_oarp->ranks;
    attempt.input.budget = m_bar;
    attempt.method = ChooseRankMethod(options, w);
    attempt.start = absl::Now();
    ASSIGN_OR_RETURN(bool planned, replan_internal::ReplanRanks(rest, attempt, options, out));
    if (!planned) {
      st.greedy_detours.push_back(k);
      continue;
    }
    if (estimator != nullptr && w.CountFree() > 0 && st.new_ranks > 0) {
      // Trivial replans (nothing to repartition) would teach it nothing.
      estimator->Record(st.new_ranks, absl::ToDoubleSeconds(absl::Now() - attempt.start));
    }
    st.method = ReplanMethodName(options.method);
    if (options.method == ReplanMethod::kAuto) {
      st.method = attempt.method == RankReplanMethod::kIlp1 ? "auto/ilp1" : "auto/ilp2";
    }
    st.replanned_encounter = k;
    st.time_to_encounter_s = tau;
    return true;
  }
  return false;
}

// Statistics of the new plan, from its path.
void FinishStats(const Remainder& rest, absl::Time start, ReplanResult* out) {
  const ReplanStats& st = out->stats;
  const Grid& drive = *rest.drive;
  const PlanStats& old = rest.old->plan.stats;
  PlanStats& s = out->plan.stats;
  s = ComputePathStats(out->plan.path, rest.robot);
  s.grid_rows = drive.rows();
  s.grid_cols = drive.cols();
  s.free_cells = st.remaining_cells;
  std::vector<uint8_t> swept(static_cast<size_t>(drive.size()), 0);
  for (const CoverageSweep& sw : out->plan.sweeps) {
    for (const CellIndex& cell : sw.cells) {
      s.covered_cells += !swept[drive.Index(cell.row, cell.col)];
      swept[drive.Index(cell.row, cell.col)] = 1;
    }
  }
  s.num_ranks = st.new_ranks + st.kept_ranks;
  s.unreachable_free_cells = out->area->unreachable_cells;
  s.mission_covered_cells = old.mission_covered_cells + st.covered_cells_before;
  s.mission_cut_off_cells = old.mission_cut_off_cells + st.newly_unreachable_cells;
  s.mission_obstructed_cells = old.mission_obstructed_cells + st.newly_obstructed_cells;
  s.map_free_area_m2 = old.map_free_area_m2;
  s.partition_ms = st.rank_replan_ms;
  s.transitions_ms = st.transitions_ms;
  s.tour_ms = st.tour_ms;
  out->stats.total_ms = MsSince(start);
  s.planning_ms = out->stats.total_ms;
  s.partition_solver = st.method;
  s.tour_solver = "gtsp";
}

}  // namespace

const char* ReplanMethodName(ReplanMethod m) {
  switch (m) {
    case ReplanMethod::kAuto:
      return "auto";
    case ReplanMethod::kIlp1:
      return "ilp1";
    case ReplanMethod::kIlp2:
      return "ilp2";
    case ReplanMethod::kGreedyDetour:
      return "greedy_detour";
    case ReplanMethod::kFull:
      return "full";
  }
  return "unknown";
}

absl::StatusOr<ReplanResult> Remaining(const RetainedPlan& old, const RobotProgress& progress,
                                       const Observations& observations) {
  if (old.area == nullptr || old.area->drive == nullptr) {
    return absl::FailedPreconditionError("the plan has no coverage area to continue from");
  }
  ReplanResult out;
  RETURN_IF_ERROR(replan_internal::ComputeRemainder(old, progress, observations, &out).status());
  return out;
}

absl::StatusOr<ReplanResult> Replan(const RetainedPlan& old, const RobotProgress& progress,
                                    const Observations& observations, const ReplanOptions& options,
                                    ReplanEstimator* estimator) {
  const absl::Time start = absl::Now();
  RETURN_IF_ERROR(CheckReplannable(old, options.method));
  ReplanResult out;
  ASSIGN_OR_RETURN(const Remainder rest,
                   replan_internal::ComputeRemainder(old, progress, observations, &out));
  out.plan.planner = "oarp-replan";
  out.plan.grid = rest.drive;
  // GREEDY_DETOUR over everything, computed first (it is cheap): the answer
  // whenever nothing better is ready in time.
  const Walk whole = replan_internal::GreedyWalk(*old.area->drive, *rest.drive, rest.legs,
                                                 rest.at.at, rest.at.heading);
  out.stats.num_encounters = whole.encounters;
  // The call's own deadline, less the time kept for building the reply.
  const StopToken call_stop =
      options.stop.has_deadline()
          ? options.stop.WithEarlierDeadline(options.stop.deadline() -
                                             absl::Seconds(options.safety_margin_s))
          : options.stop;
  bool done = false;
  if (options.method == ReplanMethod::kGreedyDetour || whole.encounters == 0) {
    replan_internal::UseGreedyDetour(rest, whole, &out);
    if (whole.encounters == 0) out.stats.method = "unchanged";
    done = true;
  } else if (options.method == ReplanMethod::kFull) {
    // OARP-Original: a new partition of everything left, toured from the robot.
    ASSIGN_OR_RETURN(done, replan_internal::ReplanFull(rest, options, call_stop, &out));
  } else {
    ASSIGN_OR_RETURN(done, RunAlgorithm1(rest, whole, options, call_stop, start, estimator, &out));
  }
  if (!done) replan_internal::UseGreedyDetour(rest, whole, &out);
  FinishStats(rest, start, &out);
  return out;
}

absl::Status ValidateObservations(const Grid& grid, const Observations& observations) {
  return replan_internal::BlockedCells(grid, observations).status();
}

absl::StatusOr<ReplanResult> Resume(const RetainedPlan& old, const RobotProgress& stopped_at,
                                    const Pose2& robot, const Observations& observations,
                                    const ReplanOptions& options, ReplanEstimator* estimator,
                                    double* rejoin_m) {
  const absl::Time start = absl::Now();
  if (!std::isfinite(robot.x) || !std::isfinite(robot.y) || !std::isfinite(robot.theta)) {
    return absl::InvalidArgumentError("pose: x, y and theta must be finite");
  }
  // The remainder from the stop point (its budgets count from there, which
  // only leaves more time: the robot first drives back).
  ASSIGN_OR_RETURN(ReplanResult out, Replan(old, stopped_at, observations, options, estimator));
  if (out.plan.path.empty() || out.area == nullptr || out.area->drive == nullptr) {
    return absl::InternalError("replan returned no path to resume");
  }
  const Grid& drive = *out.area->drive;
  const Waypoint stop = out.plan.path.front();
  // The drive grid is the free area connected to where the robot stopped.
  absl::StatusOr<CellIndex> joined = JoinCell(drive, robot, "pose");
  if (!joined.ok()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "pose: the robot at (%.3f, %.3f) is neither in nor next to a free cell from which it can "
        "drive to "
        "where it stopped (%.3f, %.3f); obstacles reported on the way may cut it off",
        robot.x, robot.y, stop.x, stop.y));
  }
  std::vector<Waypoint> path = {{robot.x, robot.y, robot.theta, SegmentKind::kStart, -1}};
  ASSIGN_OR_RETURN(bool routed, replan_internal::AppendRoute(drive, {robot.x, robot.y},
                                                             Pose2{stop.x, stop.y, stop.theta},
                                                             options.stop, &path));
  if (!routed)
    return absl::DeadlineExceededError("no time left to route the robot back to where it stopped");
  const Point2 reached{path.back().x, path.back().y};
  if (std::hypot(reached.x - stop.x, reached.y - stop.y) > 1e-6) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "pose: the robot at (%.3f, %.3f) cannot reach where it stopped (%.3f, %.3f)", robot.x,
        robot.y, stop.x, stop.y));
  }
  double back = 0.0;
  for (size_t i = 1; i < path.size(); ++i)
    back += std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  if (rejoin_m != nullptr) *rejoin_m = back;
  const int offset = static_cast<int>(path.size()) - 1;
  for (size_t i = 1; i < out.plan.path.size(); ++i) path.push_back(out.plan.path[i]);
  for (CoverageSweep& s : out.plan.sweeps) s.waypoint += offset;
  out.plan.path = std::move(path);
  PlanStats& s = out.plan.stats;
  const PlanStats moved = ComputePathStats(out.plan.path, old.request.common.robot);
  s.num_turns = moved.num_turns;
  s.coverage_length_m = moved.coverage_length_m;
  s.transition_length_m = moved.transition_length_m;
  s.estimated_duration_s = moved.estimated_duration_s;
  s.turning_time_s = moved.turning_time_s;
  out.stats.total_ms = MsSince(start);
  s.planning_ms = out.stats.total_ms;
  return out;
}

}  // namespace covplan
