// On-line and ant-like STC (Gabriely & Rimon §2.2-2.3) on a simulated robot.
//
// The robot stands in a tool-size sub-cell of a true grid it does not know.
// Its sensor reads the four coarse cells around its coarse cell (their
// sub-cells and whether the robot can cross into them); it moves one
// sub-cell at a time and the simulator refuses any move the truth blocks.
//
//  - On-line STC builds the spanning tree by DFS as it moves (O(N) memory:
//    the tree and the sensed map). It follows the same counter-clockwise
//    circumnavigation as the off-line planner, so the tree is the off-line
//    DFS tree; partly free coarse cells are covered as off-line, gaps bridged
//    by shortest paths over the cells it has sensed (a sub-cell with no
//    sensed way in yet is visited after the walk, when all are sensed).
//  - Ant-like STC stores no tree: it marks each sub-cell as it leaves it and
//    finds a cell's parent from the unmarked -> marked transition of the
//    cell's sub-cells in counter-clockwise order; its memory is the current
//    cell, the side it entered by and the start. Parent detection needs the
//    fixed four-sub-cell pattern, so it covers wholly free coarse cells only
//    (PartialCells::kDiscard), as in the paper.
//
//   SubCellRobot robot(truth, start);
//   ASSIGN_OR_RETURN(OnlineStcStats st, RunOnlineStc(&robot, PartialCells::kCover));
//   robot.trail();  // every sub-cell the robot stood in, in order
//
// Coarse cells start at row 0, column 0 of the true grid (the robot cannot
// choose an offset for a map it does not know).
// Thread-safety: a SubCellRobot is single-threaded.
#ifndef COVPLAN_PLANNER_STC_ONLINE_STC_H_
#define COVPLAN_PLANNER_STC_ONLINE_STC_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/grid/grid.h"
#include "planner/stc/coarse_grid.h"

namespace covplan {

class SubCellRobot {
 public:
  // `truth` must outlive the robot; `start` must be a free cell.
  SubCellRobot(const Grid& truth, CellIndex start);

  CellIndex at() const { return at_; }
  // One move to a 4-neighbour. FailedPrecondition when the truth blocks it
  // (off the map, into an obstacle, through a thin wall).
  absl::Status Step(CellIndex to);
  // Every cell the robot stood in, the start first.
  const std::vector<CellIndex>& trail() const { return trail_; }

  // The sensor: the coarse cell `id` as the truth has it (read only for the
  // robot's own coarse cell and its four neighbours; counted).
  uint8_t SenseFreeBits(const CoarseGrid& truth_coarse, int id);
  int64_t sensor_reads() const { return sensor_reads_; }

  // Markers (ant-like STC): left in the cell the robot stands in.
  void MarkHere() { marked_[truth_.Index(at_.row, at_.col)] = 1; }
  bool Marked(CellIndex c) const {
    return truth_.IsFree(c) && marked_[truth_.Index(c.row, c.col)] != 0;
  }

  const Grid& truth() const { return truth_; }

 private:
  const Grid& truth_;
  CellIndex at_;
  std::vector<CellIndex> trail_;
  std::vector<uint8_t> marked_;
  int64_t sensor_reads_ = 0;
};

struct OnlineStcStats {
  int64_t steps = 0;
  int64_t tree_edges = 0;        // on-line: edges stored; ant-like: edges crossed into new cells
  int64_t max_stored_cells = 0;  // on-line: sensed coarse cells kept; ant-like: 0
  // On-line: sub-cells reached only after the walk, because every known way
  // in led through cells not sensed yet.
  int64_t deferred_cells = 0;
};

// On-line STC from the robot's cell to the end of the circumnavigation (the
// start cell). Every cell of the truth's coarse nodes reachable by the tree
// is covered (all free cells with PartialCells::kCover).
absl::StatusOr<OnlineStcStats> RunOnlineStc(SubCellRobot* robot, PartialCells partial);

// Ant-like STC (wholly free coarse cells only; see above). The robot must
// start in a wholly free coarse cell.
absl::StatusOr<OnlineStcStats> RunAntStc(SubCellRobot* robot);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_STC_ONLINE_STC_H_
