// The geometry of replanning (internal to planner/replan): where the robot is
// on its plan, which cells the new obstacles block, the remainder of the old
// path as legs, the greedy walk that drives that remainder with a detour
// around every blocked stretch (finishing interrupted ranks after it), and
// the route over the new drive grid that joins a path to a pose.
//
// Thread-safety: plain functions over immutable inputs.
#ifndef COVPLAN_PLANNER_REPLAN_REPLAN_WALK_H_
#define COVPLAN_PLANNER_REPLAN_REPLAN_WALK_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/engine/site.h"
#include "planner/plan/coverage_plan.h"
#include "planner/replan/replanner.h"
#include "planner/tour/grid_paths.h"

namespace covplan::replan_internal {

// One straight segment of the remaining path.
struct Leg {
  Point2 a, b;
  SegmentKind kind = SegmentKind::kTransition;
  int old_segment = -1;          // index of the old path's waypoint this leg ends at
  int tag = -1;                  // the old waypoint's rank tag
  bool whole = true;             // the leg is a whole old segment (not cut by the robot)
  std::vector<CellIndex> cells;  // coverage: cells swept, ordered from a to b
};

struct Located {
  int segment = 1;  // the old segment path[segment - 1] -> path[segment]
  double t = 0.0;   // position on it, 0..1
  Point2 at;
  double heading = 0.0;
};

absl::StatusOr<Located> Locate(const CoveragePlan& plan, const RobotProgress& progress);

// Per drive-grid cell: 1 when a new obstacle blocks a free cell (the robot's
// own cell included: Replan lets the robot leave it, as a dock cell).
absl::StatusOr<std::vector<uint8_t>> BlockedCells(const Grid& drive, const Observations& obs);

// The old path from the robot on, as legs; `covered` gets 1 for every cell
// swept before the robot's position.
std::vector<Leg> RemainingLegs(const CoveragePlan& plan, const Located& at,
                               std::vector<uint8_t>* covered);

using ::covplan::SegmentTouches;  // planner/tour/grid_paths.h

// A cell a replanned path must not touch: free on the old drive grid, not on
// the new one (a new obstacle, or cut off by one), or off the grid. Cells
// that were never free (a dock's cell, which the old path left by its join
// move) stay open.
bool NewlyClosed(const Grid& old_drive, const Grid& drive, int r, int c);

// Appends transitions from `from` to `to` over `drive` (an any-angle search
// between the cells both join the grid at); false when `stop` ended the
// search. InvalidArgument (JoinCell's, naming "start" or "end") when an end
// is neither in nor next to a free cell.
absl::StatusOr<bool> AppendRoute(const Grid& drive, Point2 from, const Pose2& to,
                                 const StopToken& stop, std::vector<Waypoint>* path);

// The greedy walk over `legs`: drives the old path and, around every
// stretch that touches a cell the new obstacles closed (free on old_drive,
// not on drive), detours over `drive` and finishes the interrupted leg (a
// detour back onto a kToStation / kFromStation leg takes that leg's kind, so
// a battery plan's station legs stay recognisable; other detours are
// kTransition). It
// records where it stood at each encounter, so the prefix up to encounter k
// is Prefix(k) without walking again.
struct Walk {
  struct Snapshot {
    size_t path_size = 0;
    size_t sweeps_size = 0;
    Point2 end;
    double heading = 0.0;
    int leg = -1;
  };
  std::vector<Waypoint> path;  // from the robot
  std::vector<CoverageSweep> sweeps;
  std::vector<uint8_t> swept;  // per cell
  int encounters = 0;          // blocked stretches met
  bool stopped = false;        // a prefix: stops at an encounter
  Point2 end;
  double end_heading = 0.0;
  int end_leg = -1;  // leg where the walk ends
  std::vector<Snapshot> at_encounter;

  // The walk up to (not into) encounter k.
  Walk Prefix(int k, const Grid& drive) const;
};
Walk GreedyWalk(const Grid& old_drive, const Grid& drive, const std::vector<Leg>& legs,
                Point2 robot, double heading);

}  // namespace covplan::replan_internal

#endif  // COVPLAN_PLANNER_REPLAN_REPLAN_WALK_H_
