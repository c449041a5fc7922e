#include "planner/sim/obstacle_crossings.h"

#include <cmath>

namespace covplan::sim_internal {
namespace {

Point2 At(const Waypoint& w) { return {w.x, w.y}; }

// Calls f(point, metres into the segment, segment length) at the centres of
// the quarter-pixel steps of each segment of `path`, segment by segment.
template <typename F>
void SampleSegments(const OccupancyMap& map, const std::vector<Waypoint>& path, F f) {
  const double step = map.resolution() / 4;
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 a = At(path[i - 1]), b = At(path[i]);
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int n = static_cast<int>(std::ceil(len / step));
    for (int k = 0; k < n; ++k) {
      const double t = (k + 0.5) / n;
      f(static_cast<int>(i), Point2{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}, t * len,
        len / n);
    }
  }
}

}  // namespace

bool InsideObstacle(const OccupancyMap& map, Point2 p) {
  const double res = map.resolution();
  const double x = (p.x - map.origin().x) / res, y = (p.y - map.origin().y) / res;
  auto blocked = [&](double px, double py) {
    const int c = static_cast<int>(std::floor(px)), r = static_cast<int>(std::floor(py));
    return c < 0 || r < 0 || c >= map.width() || r >= map.height() || !map.IsFree(r, c);
  };
  constexpr double kNudge = 1e-6;  // pixels
  return blocked(x - kNudge, y - kNudge) && blocked(x + kNudge, y - kNudge) &&
         blocked(x - kNudge, y + kNudge) && blocked(x + kNudge, y + kNudge);
}

std::vector<PathCrossing> SmallObstacleCrossings(const OccupancyMap& map, const Grid& grid,
                                                 const std::vector<Waypoint>& path) {
  std::vector<PathCrossing> out;
  int segment = 0;
  bool inside = false;
  SampleSegments(map, path, [&](int i, Point2 p, double along, double) {
    const bool was = inside && i == segment;
    segment = i;
    inside = InsideObstacle(map, p);
    if (!inside || was) return;
    const CellIndex c = grid.CellAt(p);
    if (grid.InBounds(c.row, c.col) && grid.IsFree(c)) out.push_back({i, along, p, c});
  });
  return out;
}

double LengthInObstacles(const OccupancyMap& map, const std::vector<Waypoint>& path) {
  double inside = 0.0;
  SampleSegments(map, path, [&](int i, Point2 p, double, double step) {
    if (InsideObstacle(map, p)) inside += step;
  });
  return inside;
}

}  // namespace covplan::sim_internal
