// OARP-Replan (thesis ch. 4; ../shared/docs/algorithms.md §4): a robot
// driving a retained plan reports obstacles its map did not show; replan the
// uncovered remainder inside the time the robot needs to reach them.
//
//   Observations seen;  seen.polygons = {...};
//   RobotProgress at;   at.waypoint = 17; at.position = {3.2, 4.0};
//   ReplanOptions opts; opts.method = ReplanMethod::kAuto; opts.stop = deadline;
//   ASSIGN_OR_RETURN(ReplanResult r, Replan(*retained, at, seen, opts, &estimator));
//   r.plan.path  // starts at the robot, covers what is left, ends at the old end
//
// Methods: kGreedyDetour drives around every encounter and finishes the
// interrupted ranks (no search); kIlp1 / kIlp2 run Algorithm 1 with that
// RANK-REPLAN (encounters in path order, each with the rank budget its
// time-to-reach allows; greedy detour for encounters with too little time);
// kAuto is Algorithm 1 choosing ILP-1 on small remainders and ILP-2 on large
// ones; kFull re-runs OARP on the remainder with no budget (the thesis's
// OARP-Original: the robot waits for it).
//
// Thread-safety: Replan is reentrant; the estimator is thread-safe.
#ifndef COVPLAN_PLANNER_REPLAN_REPLANNER_H_
#define COVPLAN_PLANNER_REPLAN_REPLANNER_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "planner/geometry/area.h"
#include "planner/replan/estimator.h"

namespace covplan {

enum class ReplanMethod { kAuto, kIlp1, kIlp2, kGreedyDetour, kFull };
const char* ReplanMethodName(ReplanMethod m);

// Where the robot is on the plan it is driving. Give the segment it is on
// (`waypoint` = index of the waypoint the current segment ends at, >= 1) with
// its position, or the distance driven along the path.
struct RobotProgress {
  int waypoint = -1;
  std::optional<double> distance_m;
  std::optional<Point2> position;  // map frame; required with `waypoint`
  // How far the position may lie from the segment (default: one cell).
  std::optional<double> tolerance_m;
};

// Obstacles the map did not show, in map coordinates.
struct Observations {
  std::vector<CellIndex> cells;        // grid cells of the plan's grid
  std::vector<Point2> points;          // the cell containing each point is blocked
  std::vector<PolygonInput> polygons;  // every cell overlapping a polygon is blocked
  bool empty() const { return cells.empty() && points.empty() && polygons.empty(); }
};

struct ReplanOptions {
  ReplanMethod method = ReplanMethod::kAuto;
  StopToken stop;  // the call's deadline / cancellation
  uint64_t seed = 1;
  int num_threads = 1;
  // AUTO uses ILP-1 while its variable count stays below this, else ILP-2.
  int64_t ilp1_max_columns = 60'000;
  // Seconds kept back from each encounter's time for building the reply.
  double safety_margin_s = 0.02;
  // The tour search stops at this limit even when the encounter leaves more
  // time (the anytime GTSP otherwise paces itself to the whole budget).
  double tour_time_limit_s = 1.0;
};

struct ReplanStats {
  std::string method;                // the method that produced the plan
  int num_encounters = 0;            // entries of the remaining path into new obstacles
  std::vector<int> greedy_detours;   // encounters (0-based) handled by greedy detour
  int replanned_encounter = -1;      // the encounter the new tour starts at, or -1
  double time_to_encounter_s = 0.0;  // drive time from the robot to it (its budget)
  int64_t rank_budget = -1;          // m̄ used (-1: unlimited / not applicable)
  int64_t new_ranks = 0;
  int64_t kept_ranks = 0;        // old ranks kept unchanged
  int64_t kept_path_pieces = 0;  // maximal unchanged sections of the old path kept
  double kept_path_m = 0.0;      // their length
  int64_t newly_blocked_cells = 0;
  int64_t covered_cells_before = 0;     // swept before the robot's position
  int64_t remaining_cells = 0;          // still to cover, reachable
  int64_t newly_unreachable_cells = 0;  // to cover but cut off by the new obstacles
  int64_t newly_obstructed_cells = 0;   // to cover but occupied by the new obstacles
  double remaining_free_area_m2 = 0.0;  // free area of the remaining cells
  double rank_replan_ms = 0.0;
  double transitions_ms = 0.0;
  double tour_ms = 0.0;
  double total_ms = 0.0;
  bool rank_lp_integral = true;  // the RANK-REPLAN relaxation was integral
  bool end_moved = false;  // the old end was cut off: the plan ends at the nearest reachable cell
  // The robot's own cell was reported blocked: it is blocked from now on and
  // the plan leaves it first (robot_cell_blocked), by a straight move to an
  // adjacent free cell that clips no other blocked cell, into the side with
  // the most cells still to cover (the others are cut off). When no such
  // move exists the robot is walled in: the cell it joins the grid at stays
  // free so that the robot can move at all (robot_cell_kept_free); the plan
  // leaves through it, or, when that is the robot's own cell, stays there.
  bool robot_cell_blocked = false;
  bool robot_cell_kept_free = false;
};

struct ReplanResult {
  CoveragePlan plan;                         // starts at the robot
  std::shared_ptr<const CoverageArea> area;  // drive/cover grids of the remainder
  std::vector<CellIndex> unreachable;        // cells to cover cut off by the new obstacles
  ReplanStats stats;
};

// InvalidArgument for malformed progress (index past the end, a position off
// the path, NaN) or observations (cells outside the grid, NaN points, bad
// polygons), naming the field; FailedPrecondition when the old plan is not
// an OARP plan with its coverage area, or is a battery plan (charge cycles or
// station legs) and the method is not kGreedyDetour. The greedy detour of a
// battery plan drives its old legs, station legs included, around the new
// obstacles; the result has no `cycles` and no energy figures (its energy
// is not re-checked against the battery: the caller knows the charge). Running out of time is not
// an error: the greedy detour answers.
absl::StatusOr<ReplanResult> Replan(const RetainedPlan& old, const RobotProgress& progress,
                                    const Observations& observations, const ReplanOptions& options,
                                    ReplanEstimator* estimator);

// What is left of `old` with the robot at `progress` and the obstacles in
// `observations`, without planning: `area` (the drive grid less the
// obstacles, cut to the robot's component, and as its cover grid the cells
// still to sweep that the robot can reach), `unreachable` (cells to cover cut
// off) and the stats that describe the remainder. For any planner's plan with
// its coverage area (FailedPrecondition without one); InvalidArgument as
// Replan for malformed progress or observations. Fleets redivide what is
// left of several robots' plans from it (planner/fleet/mission.h).
absl::StatusOr<ReplanResult> Remaining(const RetainedPlan& old, const RobotProgress& progress,
                                       const Observations& observations);

// The checks Replan applies to `observations` on a plan of `grid`'s size
// (cells inside the grid, finite points, valid polygons), without planning.
absl::Status ValidateObservations(const Grid& grid, const Observations& observations);

// Resume an interrupted plan (battery swap, e-stop, restart): the robot
// stopped at `stopped_at` on `old` and now stands at `robot` (anywhere in or
// next to a free cell, e.g. on its dock). The plan drives from `robot` back
// to where it stopped, then on over what it had not covered, replanning
// around `observations` as Replan does. `rejoin_m` (optional) receives the
// length of the drive back. InvalidArgument names `pose` when the robot is
// off the grid or cannot reach the stop point.
absl::StatusOr<ReplanResult> Resume(const RetainedPlan& old, const RobotProgress& stopped_at,
                                    const Pose2& robot, const Observations& observations,
                                    const ReplanOptions& options, ReplanEstimator* estimator,
                                    double* rejoin_m = nullptr);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_REPLAN_REPLANNER_H_
