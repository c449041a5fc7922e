// Test helper of the simulator tests: the true map's grid, a check that a
// driven path never enters a cell it blocks, and whether a cell holds an
// obstacle pixel.
// Thread-safety: stateless.
#ifndef COVPLAN_TESTS_SIM_SIM_CHECKS_H_
#define COVPLAN_TESTS_SIM_SIM_CHECKS_H_

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"

namespace covplan::testing {

inline Grid TrueGrid(const OccupancyMap& truth, double cell_m = 0.8) {
  GridOptions go;
  go.cell_size = cell_m;
  absl::StatusOr<Grid> g = BuildGrid(truth, go);
  EXPECT_TRUE(g.ok()) << g.status();
  return *g;
}

// First driven point (every 1 % of a cell) strictly inside a cell the true grid
// blocks, after the robot has left the cell it started in; "" if none.
inline std::string FirstBlockedPoint(const Grid& grid, const std::vector<Waypoint>& path) {
  const CellIndex start = path.empty() ? CellIndex{} : grid.CellAt({path[0].x, path[0].y});
  bool left_start = false;
  for (size_t i = 1; i < path.size(); ++i) {
    const Waypoint& a = path[i - 1];
    const Waypoint& b = path[i];
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(b.x - a.x, b.y - a.y) /
                                                         (grid.cell_size() / 100))));
    for (int k = 0; k <= n; ++k) {
      const Point2 p{a.x + (b.x - a.x) * k / n, a.y + (b.y - a.y) * k / n};
      const double fx = (p.x - grid.origin().x) / grid.cell_size(),
                   fy = (p.y - grid.origin().y) / grid.cell_size();
      const double border = std::min(
          {fx - std::floor(fx), std::ceil(fx) - fx, fy - std::floor(fy), std::ceil(fy) - fy});
      if (border < 1e-6) continue;  // on a cell border: in no cell
      const CellIndex c = grid.CellAt(p);
      if (c != start) left_start = true;
      if ((c != start || left_start) && !grid.IsFree(c)) {
        return "segment " + std::to_string(i) + " enters blocked cell (" + std::to_string(c.row) +
               ", " + std::to_string(c.col) + ") at (" + std::to_string(p.x) + ", " +
               std::to_string(p.y) + ")";
      }
    }
  }
  return "";
}

// A pixel of `truth` whose centre lies in `cell` of `grid` is not free:
// the cell holds an obstacle, however small.
inline bool CellHoldsObstacle(const OccupancyMap& truth, const Grid& grid, CellIndex cell) {
  const double res = truth.resolution();
  for (int r = 0; r < truth.height(); ++r) {
    const double y = truth.origin().y + (r + 0.5) * res;
    for (int c = 0; c < truth.width(); ++c) {
      const Point2 p{truth.origin().x + (c + 0.5) * res, y};
      if (!truth.IsFree(r, c) && grid.CellAt(p) == cell) return true;
    }
  }
  return false;
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SIM_SIM_CHECKS_H_
