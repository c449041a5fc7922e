#include "planner/geometry/grid_scan.h"

#include <algorithm>
#include <cmath>

namespace covplan::geometry_internal {
namespace {

// floor(v) clamped to [lo, hi]; NaN gives lo.
int FloorClamped(double v, int lo, int hi) {
  if (!(v >= lo)) return lo;
  if (v >= hi) return hi;
  return std::clamp(static_cast<int>(std::floor(v)), lo, hi);
}

}  // namespace

GridScanner::GridScanner(const AreaData& data, const GridFrame& frame)
    : data_(data), frame_(frame), slack_(1e-6 * frame.cell) {
  const double cell = frame.cell;
  row_begin_ = FloorClamped((data.min_corner.y - frame.origin.y) / cell, 0, frame.rows);
  row_end_ = std::max(row_begin_,
                      FloorClamped((data.max_corner.y - frame.origin.y) / cell + 1, 0, frame.rows));
  col_begin_ = FloorClamped((data.min_corner.x - frame.origin.x) / cell, 0, frame.cols);
  col_end_ = std::max(col_begin_,
                      FloorClamped((data.max_corner.x - frame.origin.x) / cell + 1, 0, frame.cols));
  if (row_begin_ == row_end_ || col_begin_ == col_end_) {
    row_end_ = row_begin_;
    col_end_ = col_begin_;
    return;
  }
  row_edges_.resize(row_end_ - row_begin_);
  boundary_.assign(col_end_ - col_begin_, 0);
  for (size_t i = 0; i < data.edges.size(); ++i) {
    const Edge& e = data.edges[i];
    const double lo = (std::min(e.a.y, e.b.y) - slack_ - frame.origin.y) / cell;
    const double hi = (std::max(e.a.y, e.b.y) + slack_ - frame.origin.y) / cell;
    if (hi < row_begin_ || lo >= row_end_) continue;
    const int r0 = FloorClamped(lo, row_begin_, row_end_ - 1);
    const int r1 = FloorClamped(hi, row_begin_, row_end_ - 1);
    for (int r = r0; r <= r1; ++r) row_edges_[r - row_begin_].push_back(static_cast<uint32_t>(i));
  }
}

void GridScanner::LoadRow(int r) {
  row_ = r;
  for (int c : marked_) boundary_[c - col_begin_] = 0;
  marked_.clear();
  crossings_.clear();
  const double cell = frame_.cell;
  const double y0 = frame_.Y(r) - slack_;
  const double y1 = frame_.Y(r + 1) + slack_;
  centre_y_ = frame_.origin.y + (r + 0.5) * cell;
  for (uint32_t i : row_edges()) {
    const Edge& e = data_.edges[i];
    const double dx = e.b.x - e.a.x, dy = e.b.y - e.a.y;
    double xa = e.a.x, xb = e.b.x;
    if (dy != 0.0) {
      const double t0 = (y0 - e.a.y) / dy, t1 = (y1 - e.a.y) / dy;
      const double tlo = std::clamp(std::min(t0, t1), 0.0, 1.0);
      const double thi = std::clamp(std::max(t0, t1), 0.0, 1.0);
      xa = e.a.x + tlo * dx;
      xb = e.a.x + thi * dx;
      if ((e.a.y > centre_y_) != (e.b.y > centre_y_)) {
        crossings_.push_back(e.a.x + (centre_y_ - e.a.y) * dx / dy);
      }
    } else if (e.a.y < y0 || e.a.y > y1) {
      continue;
    }
    const double lo = (std::min(xa, xb) - slack_ - frame_.origin.x) / cell;
    const double hi = (std::max(xa, xb) + slack_ - frame_.origin.x) / cell;
    if (hi < col_begin_ || lo >= col_end_) continue;
    const int c0 = FloorClamped(lo, col_begin_, col_end_ - 1);
    const int c1 = FloorClamped(hi, col_begin_, col_end_ - 1);
    for (int c = c0; c <= c1; ++c) {
      uint8_t& b = boundary_[c - col_begin_];
      if (!b) {
        b = 1;
        marked_.push_back(c);
      }
    }
  }
  std::sort(crossings_.begin(), crossings_.end());
}

bool GridScanner::InsideAtCentreLine(double x) const {
  const auto n = std::lower_bound(crossings_.begin(), crossings_.end(), x) - crossings_.begin();
  return n % 2 == 1;
}

}  // namespace covplan::geometry_internal
