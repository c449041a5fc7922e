// Ranks: maximal straight runs of equally-oriented grid cells, each covered
// by one straight pass of the tool.
//
// Thread-safety: plain value types.
#ifndef COVPLAN_PLANNER_PARTITION_RANK_H_
#define COVPLAN_PLANNER_PARTITION_RANK_H_

#include <cstdint>
#include <vector>

#include "planner/grid/grid.h"

namespace covplan {

enum class Orientation : uint8_t { kHorizontal = 0, kVertical = 1 };

struct Rank {
  Orientation orientation = Orientation::kHorizontal;
  CellIndex first;  // lowest col (H) or lowest row (V)
  CellIndex last;   // highest col (H) or highest row (V)
  int NumCells() const {
    return orientation == Orientation::kHorizontal ? last.col - first.col + 1
                                                   : last.row - first.row + 1;
  }
};

// An orientation per free cell plus the ranks it induces.
struct RankPartition {
  std::vector<uint8_t>
      orientation;  // per grid cell (Grid::Index); 0 = H, 1 = V; ignored for blocked cells
  std::vector<Rank> ranks;
  double objective = 0.0;  // optimum reported by the solver (== ranks.size())

  size_t MemoryBytes() const {
    return sizeof(*this) + orientation.capacity() + ranks.capacity() * sizeof(Rank);
  }
};

// Merges consecutive equally-oriented free cells into ranks. Order: all H
// ranks row by row, then all V ranks column by column.
std::vector<Rank> RanksFromOrientation(const Grid& grid, const std::vector<uint8_t>& orientation);

// Number of rank starts the thesis objective counts for an orientation
// assignment (equals RanksFromOrientation(...).size()).
int64_t CountRankStarts(const Grid& grid, const std::vector<uint8_t>& orientation);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_RANK_H_
