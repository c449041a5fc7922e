#include "planner/stc/coarse_grid.h"

namespace covplan {

CoarseGrid::CoarseGrid(const Grid& drive, const Grid& cover, CellIndex offset, PartialCells partial)
    : drive_(&drive), offset_(offset), partial_(partial) {
  rows_ = (drive.rows() + offset.row + 1) / 2;
  cols_ = (drive.cols() + offset.col + 1) / 2;
  free_.assign(size(), 0);
  target_.assign(size(), 0);
  node_.assign(size(), 0);
  for (int id = 0; id < size(); ++id) {
    for (int p = 0; p < 4; ++p) {
      const CellIndex c = SubCell(id, p);
      if (drive.IsFree(c)) free_[id] |= 1 << p;
      if (drive.IsFree(c) && cover.IsFree(c)) target_[id] |= 1 << p;
    }
    // kCover: a node when its free sub-cells are connected inside the cell
    // (a thin wall through it, or only diagonal sub-cells, would make the
    // ring jump between rooms); the others' sub-cells are orphans.
    bool node = free_[id] != 0;
    if (node && partial_ == PartialCells::kCover) {
      uint8_t reached = static_cast<uint8_t>(free_[id] & -free_[id]);  // lowest free position
      for (int round = 0; round < 3; ++round) {
        for (int p = 0; p < 4; ++p) {
          if (!((reached >> p) & 1)) continue;
          for (int q : {(p + 1) % 4, (p + 3) % 4}) {
            if (!((free_[id] >> q) & 1)) continue;
            const CellIndex a = SubCell(id, p), b = SubCell(id, q);
            if (drive.Passable(a.row, a.col, b.row - a.row, b.col - a.col)) reached |= 1 << q;
          }
        }
      }
      node = reached == free_[id];
    }
    if (partial_ == PartialCells::kDiscard) {
      node = free_[id] == 15;
      for (int p = 0; node && p < 4; ++p) {
        const CellIndex a = SubCell(id, p), b = SubCell(id, (p + 1) % 4);
        node = drive.Passable(a.row, a.col, b.row - a.row, b.col - a.col);
      }
    }
    node_[id] = node;
    num_nodes_ += node;
    num_full_nodes_ += node && free_[id] == 15;
  }
}

int CoarseGrid::Neighbour(int id, int side) const {
  const int r = id / cols_ + kSideRow[side], c = id % cols_ + kSideCol[side];
  if (r < 0 || c < 0 || r >= rows_ || c >= cols_) return -1;
  return Id(r, c);
}

CellIndex CoarseGrid::SubCell(int id, int pos) const {
  return {2 * (id / cols_) - offset_.row + kPosRow[pos],
          2 * (id % cols_) - offset_.col + kPosCol[pos]};
}

int CoarseGrid::CoarseOf(CellIndex cell) const {
  return Id((cell.row + offset_.row) / 2, (cell.col + offset_.col) / 2);
}

int CoarseGrid::PositionOf(CellIndex cell) const {
  const int dr = (cell.row + offset_.row) % 2, dc = (cell.col + offset_.col) % 2;
  return dr == 0 ? dc : 3 - dc;
}

bool CoarseGrid::Crossable(int id, int side, int pos) const {
  const int other = Neighbour(id, side);
  if (other < 0) return false;
  const CellIndex a = SubCell(id, pos);
  return drive_->Passable(a.row, a.col, kSideRow[side], kSideCol[side]);
}

bool CoarseGrid::CanLink(int id, int side) const {
  const int other = Neighbour(id, side);
  if (other < 0 || !IsNode(id) || !IsNode(other)) return false;
  const bool first = Crossable(id, side, side), second = Crossable(id, side, (side + 1) % 4);
  if (partial_ == PartialCells::kDiscard) return first && second;
  // The ring crosses the side at both pairs: a pair of free sub-cells with a
  // thin wall between them would send the robot round through a door.
  auto walled = [&](int pos) {
    const CellIndex a = SubCell(id, pos);
    const CellIndex b{a.row + kSideRow[side], a.col + kSideCol[side]};
    return drive_->IsFree(a) && drive_->IsFree(b) &&
           !drive_->Passable(a.row, a.col, kSideRow[side], kSideCol[side]);
  };
  return (first || second) && !walled(side) && !walled((side + 1) % 4);
}

}  // namespace covplan
