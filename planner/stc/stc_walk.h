// From STC's circumnavigation to the robot's walk and to a CoveragePlan path.
//
// The circumnavigation lists every sub-cell of the tree's coarse cells once.
// Wholly free coarse cells need nothing more: consecutive sub-cells are
// neighbours, so the walk is one unit move per cell to cover. Where a coarse
// cell is partly blocked (or partly outside the regions) the walk skips the
// sub-cells that are not to be covered and bridges each gap with a shortest
// 4-neighbour path on the drive grid (BFS); a cell to cover that a bridge
// passes is covered there and skipped later. Orphan sub-cells (outside every
// tree node) cost an out-and-back move each unless one lies between two
// consecutive cells of the walk. Bridges and excursions are the only extra
// moves: each bridge is shortest for the order, and the order is the tree's.
//
//   ASSIGN_OR_RETURN(StcWalk walk, WalkForest(drive, cover, rings, orphan, start, end, stop));
//   AppendWalk(drive, walk, start_pose, end_pose, tag, &plan);
//
// Thread-safety: the functions are reentrant; a StcWalker is single-threaded.
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
  int64_t covered_cells = 0;        // distinct cells to cover visited (start included)
  int64_t extra_moves = 0;          // coverage steps that cover nothing new
  int64_t cells_covered_twice = 0;  // drive cells entered more than once within the coverage steps
};

// The robot's walk over the tool-width grid, one unit move at a time, over
// what `World` says it knows. Cells to cover outside the tree ("orphans":
// free sub-cells of coarse cells whose free sub-cells are not connected
// inside the cell, e.g. split by a thin wall or only diagonal) are swept by
// excursions from the tree cell next to them: on the way to the next tree
// cell when an orphan touches both (no extra move), else out and back.
class StcWalker {
 public:
  struct World {
    std::function<bool(CellIndex)> may_enter;           // free and known to the robot
    std::function<bool(CellIndex, int, int)> passable;  // (cell, dr, dc)
    std::function<bool(CellIndex)> to_cover;            // a cell to cover
    std::function<bool(CellIndex)> orphan;              // to cover, outside the tree
    std::function<absl::Status(CellIndex)> on_step;     // after each move (the robot drives)
  };
  StcWalker(const Grid& shape, World world, CellIndex start);

  // Goes to `next` (a tree cell to cover) unless already covered, sweeping
  // orphans on the way. NotFound when the known cells hold no path.
  absl::Status Visit(CellIndex next, const StopToken& stop);
  // Orphan excursions from where the robot stands.
  absl::Status Excursions();
  // Every cell to cover still unswept that `pending` lists, nearest first.
  absl::Status SweepRemaining(const std::vector<CellIndex>& pending, const StopToken& stop);
  // Drives to `end` (no coverage counted after the last new cell).
  absl::Status GoTo(CellIndex end);
  bool covered(CellIndex c) const { return covered_[shape_.Index(c.row, c.col)] != 0; }
  CellIndex at() const { return at_; }
  // The walk so far, with the repeat statistics filled.
  StcWalk Finish() const;

 private:
  absl::Status Step(CellIndex to);
  absl::Status Excursion(CellIndex from);
  std::vector<CellIndex> Path(CellIndex from, CellIndex to);

  const Grid& shape_;
  World world_;
  CellIndex at_;
  StcWalk walk_;
  std::vector<uint8_t> covered_;
  std::vector<uint32_t> stamp_;
  std::vector<int64_t> parent_;
  std::vector<int64_t> queue_;
  uint32_t round_ = 0;
  int64_t bridges_ = 0;
};

// Off-line, for a forest (one ring per tree, rings[0] holding the start's
// tree when it has one): walks the start's ring from the start; whenever the
// robot stands next to a cell of a tree not walked yet, that tree's ring is
// spliced in from that cell (a tree met on the way costs a step in and a
// step back instead of a trip); trees never met are walked nearest first.
// Orphans (`orphan`, per drive cell, may be empty) are swept on the way.
absl::StatusOr<StcWalk> WalkForest(const Grid& drive, const Grid& cover,
                                   const std::vector<std::vector<CellIndex>>& rings,
                                   const std::vector<uint8_t>& orphan, CellIndex start,
                                   CellIndex end, const StopToken& stop);

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
