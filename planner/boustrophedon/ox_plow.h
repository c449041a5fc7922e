// The ox-plow (back-and-forth) path over one boustrophedon cell: parallel
// coverage lines one tool width (one grid cell) apart, driven alternately
// up and down, joined by short moves inside the cell. Lines run either along
// the cell's columns (always possible: a cell is one segment per column) or
// along its rows (possible when every row of the cell is one linked run);
// ChooseAxis picks, per cell, the axis with fewer lines, hence fewer turns.
//
//   ASSIGN_OR_RETURN(SweepLines lines, BuildSweepLines(grid, cell, SweepAxis::kVertical));
//   PolylineElement e = OxPlowElement(grid, lines, /*tag=*/cell_id);
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_PLANNER_BOUSTROPHEDON_OX_PLOW_H_
#define COVPLAN_PLANNER_BOUSTROPHEDON_OX_PLOW_H_

#include <optional>
#include <vector>

#include "planner/boustrophedon/decomposition.h"
#include "planner/grid/grid.h"
#include "planner/tour/polyline_tour.h"

namespace covplan {

enum class SweepAxis { kVertical = 0, kHorizontal = 1 };

struct SweepLines {
  SweepAxis axis = SweepAxis::kVertical;
  // Each line's cells in increasing row (vertical) or column (horizontal);
  // line k + 1 is the next column (row) after line k.
  std::vector<std::vector<CellIndex>> lines;
};

// The lines of `cell` along `axis`; nullopt when that axis cannot sweep the
// cell with one straight line per row/column and linked neighbours.
std::optional<SweepLines> BuildSweepLines(const Grid& grid, const BcdCell& cell, SweepAxis axis);

// The cell's lines: along `forced` when given and possible, else along the
// axis with fewer lines (columns on a tie, and whenever rows cannot work).
SweepLines ChooseSweepLines(const Grid& grid, const BcdCell& cell, std::optional<SweepAxis> forced);

// The ox-plow polyline over `lines`: coverage segments (one per line) and
// transition moves inside the cell, tagged `tag`. Forwards starts at the
// first line's first cell, or its last cell when `mirrored`.
PolylineElement OxPlowElement(const Grid& grid, const SweepLines& lines, int tag,
                              bool mirrored = false);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_BOUSTROPHEDON_OX_PLOW_H_
