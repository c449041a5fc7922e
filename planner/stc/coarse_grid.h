// The coarse grid of Spanning Tree Coverage (Gabriely & Rimon): cells of
// twice the tool width over the engine's tool-width grid, each made of 2x2
// tool-size sub-cells, with the rules that decide which coarse cells join the
// spanning tree and which neighbours the tree may link.
//
// Sub-cells of a coarse cell are numbered counter-clockwise ("ring
// positions"): 0 bottom-left, 1 bottom-right, 2 top-right, 3 top-left (row 0
// is the smallest y). Side k runs from position k to k + 1: 0 south, 1 east,
// 2 north, 3 west. Across side k, position k faces the neighbour's position
// k + 3 and position k + 1 faces the neighbour's k + 2 (mod 4).
//
//   CoarseGrid coarse(drive, cover, {0, 1}, PartialCells::kCover);
//   for (int id = 0; id < coarse.size(); ++id) if (coarse.IsNode(id)) ...
//
// Thread-safety: immutable after construction.
#ifndef COVPLAN_PLANNER_STC_COARSE_GRID_H_
#define COVPLAN_PLANNER_STC_COARSE_GRID_H_

#include <array>
#include <cstdint>
#include <vector>

#include "planner/grid/grid.h"

namespace covplan {

// What to do with coarse cells that are not wholly free.
enum class PartialCells : uint8_t {
  kCover = 0,    // keep them in the tree; cover their free sub-cells
  kDiscard = 1,  // the paper's approximation: only wholly free coarse cells
};

class CoarseGrid {
 public:
  // `offset` shifts the coarse cells by one sub-cell: coarse cell (I, J)
  // holds rows 2I - offset.row .. +1 and columns 2J - offset.col .. +1.
  CoarseGrid(const Grid& drive, const Grid& cover, CellIndex offset, PartialCells partial);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int size() const { return rows_ * cols_; }
  CellIndex offset() const { return offset_; }
  const Grid& drive() const { return *drive_; }

  int Id(int r, int c) const { return r * cols_ + c; }
  // The neighbour across `side`, or -1 outside the coarse grid.
  int Neighbour(int id, int side) const;
  // The tool-width cell at ring position `pos` (may be out of the grid's bounds).
  CellIndex SubCell(int id, int pos) const;
  // The coarse cell and ring position of a tool-width cell.
  int CoarseOf(CellIndex cell) const;
  int PositionOf(CellIndex cell) const;

  // Bit p set: the sub-cell at ring position p is a drive cell.
  uint8_t free_bits(int id) const { return free_[id]; }
  // Bit p set: the sub-cell at ring position p is a cell to cover.
  uint8_t target_bits(int id) const { return target_[id]; }
  // The coarse cell is a node of the spanning tree: with kCover, its free
  // sub-cells are connected inside it; with kDiscard, all four are free and
  // linked around the ring.
  bool IsNode(int id) const { return node_[id] != 0; }
  // A cell to cover outside every node (kCover only; swept by excursions).
  bool IsOrphan(CellIndex c) const {
    return partial_ == PartialCells::kCover && drive_->IsFree(c) && !IsNode(CoarseOf(c));
  }
  // The tree may link `id` to its neighbour across `side` (both are nodes,
  // and the robot can cross: with kCover one passable sub-cell link on that
  // side suffices when the other pair is not two free cells split by a thin
  // wall; with kDiscard both links must be passable).
  bool CanLink(int id, int side) const;
  // The two sub-cells facing each other across `side` at ring position
  // `pos` (pos is side or side + 1) are both free and passable.
  bool Crossable(int id, int side, int pos) const;

  int num_nodes() const { return num_nodes_; }
  int num_full_nodes() const { return num_full_nodes_; }

 private:
  const Grid* drive_;
  int rows_ = 0;
  int cols_ = 0;
  CellIndex offset_;
  PartialCells partial_;
  std::vector<uint8_t> free_, target_, node_;
  int num_nodes_ = 0;
  int num_full_nodes_ = 0;
};

// Ring position helpers.
inline constexpr std::array<int, 4> kPosRow = {0, 0, 1, 1};
inline constexpr std::array<int, 4> kPosCol = {0, 1, 1, 0};
inline constexpr std::array<int, 4> kSideRow = {-1, 0, 1, 0};  // neighbour across side
inline constexpr std::array<int, 4> kSideCol = {0, 1, 0, -1};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_STC_COARSE_GRID_H_
