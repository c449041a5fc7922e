#include "planner/sim/sensor.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace covplan::sim_internal {

template <typename F>
bool RangeSensor::LineOfSight(Point2 from, Point2 to, F may_block) const {
  const double res = truth_.resolution();
  const double x0 = (from.x - truth_.origin().x) / res, y0 = (from.y - truth_.origin().y) / res;
  const double x1 = (to.x - truth_.origin().x) / res, y1 = (to.y - truth_.origin().y) / res;
  int cx = static_cast<int>(std::floor(x0)), cy = static_cast<int>(std::floor(y0));
  const int tx = static_cast<int>(std::floor(x1)), ty = static_cast<int>(std::floor(y1));
  const double dx = x1 - x0, dy = y1 - y0;
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double next_x = dx != 0 ? (sx > 0 ? cx + 1 - x0 : x0 - cx) / std::abs(dx) : kInf;
  double next_y = dy != 0 ? (sy > 0 ? cy + 1 - y0 : y0 - cy) / std::abs(dy) : kInf;
  const double step_x = dx != 0 ? 1.0 / std::abs(dx) : kInf,
               step_y = dy != 0 ? 1.0 / std::abs(dy) : kInf;
  const int max_steps = std::abs(tx - cx) + std::abs(ty - cy) + 2;
  for (int k = 0; k < max_steps && !(cx == tx && cy == ty); ++k) {
    if (next_x < next_y) {
      cx += sx, next_x += step_x;
    } else {
      cy += sy, next_y += step_y;
    }
    if (cx < 0 || cy < 0 || cx >= truth_.width() || cy >= truth_.height()) return false;
    if (truth_.IsFree(cy, cx)) continue;
    const Point2 centre{truth_.origin().x + (cx + 0.5) * res, truth_.origin().y + (cy + 0.5) * res};
    if (!may_block(centre)) return false;
  }
  return true;
}

std::vector<CellIndex> RangeSensor::Scan(Point2 position, const std::vector<uint8_t>& candidate,
                                         const std::vector<uint8_t>& found) const {
  const double s = grid_.cell_size();
  const CellIndex at = grid_.CellAt(position);
  const int reach = static_cast<int>(std::ceil(range_m_ / s)) + 1;
  std::vector<CellIndex> seen;
  for (int r = std::max(0, at.row - reach); r <= std::min(grid_.rows() - 1, at.row + reach); ++r) {
    for (int c = std::max(0, at.col - reach); c <= std::min(grid_.cols() - 1, at.col + reach);
         ++c) {
      const int64_t i = grid_.Index(r, c);
      if (!candidate[i] || found[i]) continue;
      const Point2 centre = grid_.CellCenter(r, c);
      if (std::hypot(centre.x - position.x, centre.y - position.y) > range_m_) continue;
      if (Visible(position, {r, c})) seen.push_back({r, c});
    }
  }
  return seen;
}

// Line of sight over the true map's pixels (Amanatides-Woo traversal): no
// non-free pixel between the robot and the cell centre, except inside the
// target cell itself (the obstacle that blocks it) and the robot's own pixel.
bool RangeSensor::Visible(Point2 from, CellIndex target) const {
  return LineOfSight(from, grid_.CellCenter(target),
                     [&](Point2 centre) { return grid_.CellAt(centre) == target; });
}

bool RangeSensor::Sees(Point2 from, Point2 to) const {
  if (std::hypot(to.x - from.x, to.y - from.y) > range_m_) return false;
  const double res = truth_.resolution();
  const int tx = static_cast<int>(std::floor((to.x - truth_.origin().x) / res));
  const int ty = static_cast<int>(std::floor((to.y - truth_.origin().y) / res));
  return LineOfSight(from, to, [&](Point2 centre) {
    return static_cast<int>(std::floor((centre.x - truth_.origin().x) / res)) == tx &&
           static_cast<int>(std::floor((centre.y - truth_.origin().y) / res)) == ty;
  });
}

}  // namespace covplan::sim_internal
