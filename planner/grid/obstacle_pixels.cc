#include "planner/grid/obstacle_pixels.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace covplan {

ObstaclePixels::ObstaclePixels(const OccupancyMap& map, double px_per_cell, int rows, int cols)
    : width_(map.width()),
      height_(map.height()),
      px_per_cell_(px_per_cell),
      cols_(cols),
      bits_(static_cast<size_t>((width_ * height_ + 63) / 64), 0),
      box_(static_cast<size_t>(rows) * cols, Box{kClean, 0, 0, 0}) {
  for (int64_t row = 0; row < height_; ++row) {
    for (int64_t col = 0; col < width_; ++col) {
      if (map.IsFree(static_cast<int>(row), static_cast<int>(col))) continue;
      const int64_t i = row * width_ + col;
      bits_[i >> 6] |= uint64_t{1} << (i & 63);
    }
  }
  // Pixels whose closed square [i, i+1] meets a cell's closed box [c*s, (c+1)*s]:
  // ceil(c*s) - 1 <= i <= floor((c+1)*s).
  auto range = [&](int c) {
    return std::pair<int32_t, int32_t>(
        static_cast<int32_t>(std::ceil(c * px_per_cell_ - 1e-9)) - 1,
        static_cast<int32_t>(std::floor((c + 1) * px_per_cell_ + 1e-9)));
  };
  for (int r = 0; r < rows; ++r) {
    const auto [j_lo, j_hi] = range(r);
    for (int c = 0; c < cols; ++c) {
      const auto [i_lo, i_hi] = range(c);
      Box& box = box_[static_cast<size_t>(r) * cols + c];
      for (int32_t j = j_lo; j <= j_hi; ++j) {
        for (int32_t i = i_lo; i <= i_hi; ++i) {
          if (!PixelBlocked(i, j)) continue;
          if (box.i0 == kClean) {
            box = Box{i, i, j, j};
          } else {
            box.i0 = std::min(box.i0, i), box.i1 = std::max(box.i1, i);
            box.j0 = std::min(box.j0, j), box.j1 = std::max(box.j1, j);
          }
        }
      }
    }
  }
  // Diagonal steps between centres: a segment through the corner shared by
  // four cells, blocked only if one of them is dirty and the line touches a
  // non-free pixel.
  diag_.assign(box_.size(), 0);
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      for (int dc : {1, -1}) {
        const int c2 = c + dc;
        if (c2 < 0 || c2 >= cols) continue;
        if (!CellDirty(r, c) && !CellDirty(r + 1, c2) && !CellDirty(r, c2) &&
            !CellDirty(r + 1, c)) {
          continue;
        }
        if (SegmentBlocked({c + 0.5, r + 0.5}, {c2 + 0.5, r + 1.5})) {
          diag_[static_cast<size_t>(r) * cols + c] |= dc > 0 ? 1 : 2;
        }
      }
    }
  }
}

bool ObstaclePixels::PixelSegmentBlocked(double x0, double y0, double x1, double y1) const {
  if (x0 > x1) std::swap(x0, x1), std::swap(y0, y1);
  // Sweep the pixel columns whose closed square meets [x0, x1]; in each, the
  // rows whose closed square meets the segment's y-extent over that column.
  const int64_t i_lo = static_cast<int64_t>(std::ceil(x0)) - 1;
  const int64_t i_hi = static_cast<int64_t>(std::floor(x1));
  const double dx = x1 - x0;
  for (int64_t i = i_lo; i <= i_hi; ++i) {
    double ya = y0, yb = y1;
    if (dx > 0.0) {
      const double xa = std::max(x0, static_cast<double>(i));
      const double xb = std::min(x1, static_cast<double>(i + 1));
      if (xa > xb) continue;
      ya = y0 + (y1 - y0) * ((xa - x0) / dx);
      yb = y0 + (y1 - y0) * ((xb - x0) / dx);
    }
    if (ya > yb) std::swap(ya, yb);
    const int64_t j_lo = static_cast<int64_t>(std::ceil(ya)) - 1;
    const int64_t j_hi = static_cast<int64_t>(std::floor(yb));
    for (int64_t j = j_lo; j <= j_hi; ++j) {
      if (PixelBlocked(i, j)) return true;
    }
  }
  return false;
}

bool ObstaclePixels::SegmentBlocked(Point2 a, Point2 b) const {
  const double s = px_per_cell_;
  return PixelSegmentBlocked(a.x * s, a.y * s, b.x * s, b.y * s);
}

bool ObstaclePixels::SegmentBlockedInCell(int r, int c, Point2 a, Point2 b) const {
  const Box& box = box_[static_cast<size_t>(r) * cols_ + c];
  if (box.i0 == kClean) return false;
  // Liang-Barsky: clip a + t (b - a), t in [0, 1] (pixel units), to the cell's
  // closed box and to the closed box of its non-free pixels.
  const double s = px_per_cell_;
  const double p0[2] = {a.x * s, a.y * s};
  const double d[2] = {(b.x - a.x) * s, (b.y - a.y) * s};
  const double lo[2] = {std::max(c * s, static_cast<double>(box.i0)),
                        std::max(r * s, static_cast<double>(box.j0))};
  const double hi[2] = {std::min((c + 1) * s, static_cast<double>(box.i1) + 1.0),
                        std::min((r + 1) * s, static_cast<double>(box.j1) + 1.0)};
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (p0[k] < lo[k] || p0[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - p0[k]) / d[k], tb = (hi[k] - p0[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return PixelSegmentBlocked(p0[0] + t0 * d[0], p0[1] + t0 * d[1], p0[0] + t1 * d[0],
                             p0[1] + t1 * d[1]);
}

}  // namespace covplan
