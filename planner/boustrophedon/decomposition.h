// Boustrophedon cellular decomposition (Choset & Pignon) of a grid's free
// cells. A vertical sweep line moves column by column; in each column the
// free cells form segments (maximal vertical runs linked through passable
// boundaries). A segment continues the cell of the segment to its left when
// each is the other's only horizontally linked neighbour; otherwise the
// connectivity of the slice changed there (a split or a merge around an
// obstacle) and a new cell opens. Every cell is therefore one segment per
// column over a run of consecutive columns, adjacent segments linked, and
// the cells partition the free cells.
//
//   BoustrophedonDecomposition d = Decompose(*area.cover);
//   for (const BcdCell& c : d.cells) { c.first_col ... c.columns[k].lo ... }
//
// Thread-safety: plain value types; Decompose is reentrant.
#ifndef COVPLAN_PLANNER_BOUSTROPHEDON_DECOMPOSITION_H_
#define COVPLAN_PLANNER_BOUSTROPHEDON_DECOMPOSITION_H_

#include <cstdint>
#include <vector>

#include "planner/grid/grid.h"

namespace covplan {

// Rows lo..hi (inclusive) of one column.
struct RowInterval {
  int lo = 0;
  int hi = 0;
  bool Contains(int r) const { return r >= lo && r <= hi; }
};

struct BcdCell {
  int first_col = 0;
  std::vector<RowInterval> columns;  // columns[k] is column first_col + k
  int last_col() const { return first_col + static_cast<int>(columns.size()) - 1; }
  int64_t NumCells() const;
};

struct BoustrophedonDecomposition {
  std::vector<BcdCell> cells;
  std::vector<int32_t> cell_of;  // per grid cell (row-major): its cell, -1 if not free
  size_t MemoryBytes() const;
};

BoustrophedonDecomposition Decompose(const Grid& grid);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_BOUSTROPHEDON_DECOMPOSITION_H_
