// The non-free pixels of the map a grid was built from, so that straight
// moves between cell centres can be checked against the map itself.
//
// A cell is free when most of its area is free, so a 0.6 m table can sit
// inside two free 0.8 m cells without blocking either; the thin-wall barriers
// only cover the line between 4-adjacent centres. Any-angle transitions and
// diagonal steps consult ObstaclePixels instead: a segment is clear when the
// closed segment touches no non-free (occupied, unknown or off-map) pixel.
// Cells overlapping a non-free pixel are marked "dirty" so that segments
// through clean cells cost nothing extra.
//
//   ObstaclePixels px(map, px_per_cell, rows, cols);
//   if (px.CellDirty(r, c) && px.SegmentBlockedInCell(r, c, a, b)) ...
//
// Coordinates are grid-local cell units: cell (r, c) is [c, c+1] x [r, r+1].
// Thread-safety: immutable after construction; const methods are thread-safe.
#ifndef COVPLAN_PLANNER_GRID_OBSTACLE_PIXELS_H_
#define COVPLAN_PLANNER_GRID_OBSTACLE_PIXELS_H_

#include <climits>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "planner/grid/occupancy_map.h"

namespace covplan {

class ObstaclePixels {
 public:
  ObstaclePixels(const OccupancyMap& map, double px_per_cell, int rows, int cols);

  bool CellDirty(int r, int c) const {
    return box_[static_cast<size_t>(r) * cols_ + c].i0 != kClean;
  }
  // True when the part of segment a..b (cell units) inside the closed box of
  // cell (r, c) touches a non-free pixel.
  bool SegmentBlockedInCell(int r, int c, Point2 a, Point2 b) const;
  // True when the whole closed segment a..b (cell units) touches a non-free pixel.
  bool SegmentBlocked(Point2 a, Point2 b) const;
  // Precomputed SegmentBlocked between the centres of (r, c) and the
  // diagonal neighbour (r + dr, c + dc), dr, dc in {-1, 1}; both in the grid.
  bool DiagonalBlocked(int r, int c, int dr, int dc) const {
    if (dr < 0) r -= 1, c += dc, dc = -dc;  // the same segment seen from below
    return (diag_[static_cast<size_t>(r) * cols_ + c] >> (dc > 0 ? 0 : 1)) & 1u;
  }

  // The map's pixels: width() x height(), px_per_cell() to a cell's side;
  // pixel (col, row) is [col, col+1] x [row, row+1] in pixel units from the
  // grid's origin. Off the map every pixel counts as not free.
  int64_t width() const { return width_; }
  int64_t height() const { return height_; }
  double px_per_cell() const { return px_per_cell_; }
  bool Blocked(int64_t col, int64_t row) const { return PixelBlocked(col, row); }

  size_t MemoryBytes() const {
    return sizeof(*this) + bits_.capacity() * sizeof(uint64_t) + box_.capacity() * sizeof(Box) +
           diag_.capacity();
  }

 private:
  bool PixelBlocked(int64_t col, int64_t row) const {
    if (col < 0 || row < 0 || col >= width_ || row >= height_) return true;
    const int64_t i = row * width_ + col;
    return (bits_[i >> 6] >> (i & 63)) & 1u;
  }
  // Segment in pixel units.
  bool PixelSegmentBlocked(double x0, double y0, double x1, double y1) const;

  // Bounding box, in pixel indices, of the non-free pixels whose closed
  // square meets a cell's closed box; i0 == kClean when there are none.
  struct Box {
    int32_t i0, i1, j0, j1;
  };
  static constexpr int32_t kClean = INT32_MIN;

  int64_t width_ = 0;
  int64_t height_ = 0;
  double px_per_cell_ = 1.0;
  int cols_ = 0;
  std::vector<uint64_t> bits_;  // 1 = non-free pixel, row-major, row 0 = smallest y
  std::vector<Box> box_;        // per cell
  std::vector<uint8_t> diag_;   // per cell: bit 0 up-right, bit 1 up-left blocked
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_GRID_OBSTACLE_PIXELS_H_
