// From an STC visiting order to the robot's walk and to a CoveragePlan path.
//
// The circumnavigation lists every sub-cell of the tree's coarse cells once.
// Wholly free coarse cells need nothing more: consecutive sub-cells are
// neighbours, so the walk is one unit move per cell to cover. Where a coarse
// cell is partly blocked (or partly outside the regions) the walk skips the
// sub-cells that are not to be covered and bridges each gap with a shortest
// 4-neighbour path on the drive grid (BFS); a cell to cover that a bridge
// passes is covered there and skipped later. These bridges are the only
// extra moves: each is shortest for the order, and the order is the tree's.
//
//   ASSIGN_OR_RETURN(StcWalk walk, WalkInOrder(drive, cover, order, start, end, stop));
//   AppendWalk(drive, walk, [&](CellIndex c) { return coarse.CoarseOf(c); }, &plan);
//
// Thread-safety: pure functions.
#ifndef COVPLAN_PLANNER_STC_STC_WALK_H_
#define COVPLAN_PLANNER_STC_STC_WALK_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

struct StcWalk {
  CellIndex start;
  bool start_covers = false;     // the start cell is a cell to cover
  std::vector<CellIndex> steps;  // each 4-adjacent (passable) to the one before
  std::vector<uint8_t> covers;   // per step: enters a cell to cover for the first time
  // Steps up to and including the last covering one (the rest is the leg
  // back to the start or on to the end).
  int64_t coverage_steps = 0;
  int64_t covered_cells = 0;          // distinct cells to cover visited (start included)
  int64_t extra_moves = 0;            // coverage steps that cover nothing new
  int64_t cells_covered_twice = 0;    // drive cells entered more than once within the coverage steps
};

// Visits the cells to cover among `order` in that order, from `start`
// (covered when it is a cell to cover), then drives to `end`. Internal when a
// cell cannot be reached (the drive grid is one component).
absl::StatusOr<StcWalk> WalkInOrder(const Grid& drive, const Grid& cover, const std::vector<CellIndex>& order,
                                    CellIndex start, CellIndex end, const StopToken& stop);

// Appends the walk to plan->path and plan->sweeps, merging straight runs of
// moves of one kind into one segment. The first waypoint is `start_pose`
// (then a transition to the start cell's centre) or the start cell's centre.
// `tag` gives each coverage segment's Waypoint::rank. `end_pose`, when given,
// is joined from the end cell's centre.
void AppendWalk(const Grid& drive, const StcWalk& walk, const std::optional<Pose2>& start_pose,
                const std::optional<Pose2>& end_pose, const std::function<int(CellIndex)>& tag,
                CoveragePlan* plan);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_STC_STC_WALK_H_
