// Obstacles smaller than their cells (a post, a table leg): the cell model
// keeps such a cell free, so a path through its centre runs into them. The
// crossings are found on the map's pixels; a driven robot sees one ahead
// and reports its cell, and drives through it only when closing the cell
// would cut it off from what it has still to sweep. A plan of a map that
// shows the furniture never crosses it, whatever the planner.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/grid.h"
#include "planner/sim/obstacle_crossings.h"
#include "planner/sim/simulator.h"
#include "tests/sim/sim_checks.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using sim_internal::LengthInObstacles;
using sim_internal::PathCrossing;
using sim_internal::SmallObstacleCrossings;

constexpr double kRes = 0.05;

// A free map of w x h metres, origin (0, 0).
OccupancyMap Open(double w, double h) {
  OccupancyMap map(static_cast<int>(std::lround(w / kRes)), static_cast<int>(std::lround(h / kRes)),
                   kRes, {0.0, 0.0});
  for (int r = 0; r < map.height(); ++r) {
    for (int c = 0; c < map.width(); ++c) map.set(r, c, CellState::kFree);
  }
  return map;
}

// Occupies the pixels whose centres lie in [x0, x1] x [y0, y1].
void Block(OccupancyMap* map, double x0, double y0, double x1, double y1) {
  for (int r = 0; r < map->height(); ++r) {
    for (int c = 0; c < map->width(); ++c) {
      const double x = (c + 0.5) * kRes, y = (r + 0.5) * kRes;
      if (x >= x0 && x <= x1 && y >= y0 && y <= y1) map->set(r, c, CellState::kOccupied);
    }
  }
}

std::vector<Waypoint> Line(Point2 a, Point2 b) {
  Waypoint w0, w1;
  w0.x = a.x, w0.y = a.y, w0.kind = SegmentKind::kStart;
  w1.x = b.x, w1.y = b.y, w1.kind = SegmentKind::kCoverage;
  return {w0, w1};
}

TEST(ObstacleCrossings, APostInAFreeCellIsFoundWhereThePathEntersIt) {
  OccupancyMap map = Open(8.0, 4.0);
  Block(&map, 4.3, 1.9, 4.5, 2.1);  // 4 x 4 px around cell (2, 5)'s centre (4.4, 2.0)
  const Grid grid = testing::TrueGrid(map);
  ASSERT_TRUE(grid.IsFree(CellIndex{2, 5}));
  const std::vector<PathCrossing> through =
      SmallObstacleCrossings(map, grid, Line({0.4, 2.0}, {7.6, 2.0}));
  ASSERT_EQ(through.size(), 1u);
  EXPECT_EQ(through[0].cell, (CellIndex{2, 5}));
  EXPECT_EQ(through[0].segment, 1);
  EXPECT_NEAR(through[0].at.x, 4.3, kRes / 4);
  EXPECT_NEAR(through[0].along_m, 3.9, kRes / 4);
  EXPECT_NEAR(LengthInObstacles(map, Line({0.4, 2.0}, {7.6, 2.0})), 0.2, kRes / 4);
  // Beside it: nothing; along a pixel face: touched, not entered.
  EXPECT_THAT(SmallObstacleCrossings(map, grid, Line({0.4, 1.2}, {7.6, 1.2})),
              ::testing::IsEmpty());
  EXPECT_THAT(SmallObstacleCrossings(map, grid, Line({0.4, 2.1}, {7.6, 2.1})),
              ::testing::IsEmpty());
  EXPECT_EQ(LengthInObstacles(map, Line({0.4, 2.1}, {7.6, 2.1})), 0.0);
}

TEST(ObstacleCrossings, ABlockedCellIsLeftToTheCellModel) {
  OccupancyMap map = Open(8.0, 4.0);
  Block(&map, 0.8, 1.6, 1.6, 2.4);  // all of cell (2, 1)
  const Grid grid = testing::TrueGrid(map);
  ASSERT_FALSE(grid.IsFree(CellIndex{2, 1}));
  EXPECT_THAT(SmallObstacleCrossings(map, grid, Line({0.4, 2.0}, {7.6, 2.0})),
              ::testing::IsEmpty());
  EXPECT_NEAR(LengthInObstacles(map, Line({0.4, 2.0}, {7.6, 2.0})), 0.8, kRes / 4);
}

// Whether (x, y), in pixel units, lies in the interior of the map's
// obstacles: every pixel it touches (one, two across a face, four at a
// corner) is not free or off the map. A point on the face between a free
// and an occupied pixel only touches the obstacle.
bool InsideObstacle(const OccupancyMap& map, double x, double y) {
  constexpr double kFace = 1e-6;
  const int c = static_cast<int>(std::floor(x)), r = static_cast<int>(std::floor(y));
  std::vector<int> cols = {c}, rows = {r};
  if (x - c < kFace) cols.push_back(c - 1);
  if (c + 1 - x < kFace) cols.push_back(c + 1);
  if (y - r < kFace) rows.push_back(r - 1);
  if (r + 1 - y < kFace) rows.push_back(r + 1);
  for (int rr : rows) {
    for (int cc : cols) {
      const bool off = cc < 0 || rr < 0 || cc >= map.width() || rr >= map.height();
      if (!off && map.IsFree(rr, cc)) return false;
    }
  }
  return true;
}

// The first point of `path` (every tenth of a pixel) inside the map's
// obstacles; "" when there is none. With `ranks_only`, only coverage
// segments are looked at.
std::string FirstPointInFurniture(const OccupancyMap& map, const std::vector<Waypoint>& path,
                                  bool ranks_only = false) {
  const double res = map.resolution();
  for (size_t i = 1; i < path.size(); ++i) {
    if (ranks_only && path[i].kind != SegmentKind::kCoverage) continue;
    const double ax = (path[i - 1].x - map.origin().x) / res,
                 ay = (path[i - 1].y - map.origin().y) / res;
    const double bx = (path[i].x - map.origin().x) / res, by = (path[i].y - map.origin().y) / res;
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(bx - ax, by - ay) * 10)));
    for (int k = 0; k <= n; ++k) {
      const double x = ax + (bx - ax) * k / n, y = ay + (by - ay) * k / n;
      if (InsideObstacle(map, x, y)) {
        return "segment " + std::to_string(i) + " at pixel (" + std::to_string(y) + ", " +
               std::to_string(x) + ")";
      }
    }
  }
  return "";
}

// Furniture the map shows, however small, is never driven through: a plan of
// the furnished office by every planner stops its ranks and transitions at
// chair legs and table edges (the grid's barriers and pixel checks) rather
// than crossing them.
TEST(SmallObstacles, NoPlannerCrossesTheFurnitureTheMapShows) {
  const OccupancyMap furnished = testing::LoadShippedMap("sample_office_furnished.yaml");
  for (const char* planner : {"oarp", "boustrophedon", "stc"}) {
    PlanOptions o;
    o.planner = planner;
    o.robot.tool_width_m = 0.8;
    o.time_limit_s = 0.3;
    absl::StatusOr<CoveragePlan> plan = PlanCoverage(furnished, o);
    ASSERT_TRUE(plan.ok()) << planner << ": " << plan.status();
    ASSERT_GT(plan->path.size(), 100u) << planner;
    EXPECT_EQ(FirstPointInFurniture(furnished, plan->path), "") << planner;
  }
  // The check sees furniture: the ranks of a plan of the bare office run
  // through it (ranks, because OARP's ranks do not depend on the tour
  // search's time budget, and its transitions do).
  PlanOptions o;
  o.robot.tool_width_m = 0.8;
  o.time_limit_s = 0.3;
  absl::StatusOr<CoveragePlan> bare =
      PlanCoverage(testing::LoadShippedMap("sample_office.yaml"), o);
  ASSERT_TRUE(bare.ok()) << bare.status();
  EXPECT_NE(FirstPointInFurniture(furnished, bare->path, /*ranks_only=*/true), "");
}

SimulationOptions Robot(Pose2 start) {
  SimulationOptions o;
  o.plan.robot.tool_width_m = 0.8;
  o.plan.robot.start = start;
  o.plan.time_limit_s = 0.3;
  o.replan_tour_time_limit_s = 0.2;
  return o;
}

// A post on the centre of a room's cell: the robot reports the cell, sweeps
// every other cell, and never drives through the post.
TEST(SmallObstacles, ARobotReportsThePostsCellAndDrivesAroundIt) {
  const OccupancyMap known = Open(8.0, 4.0);
  OccupancyMap truth = known;
  Block(&truth, 4.3, 1.9, 4.5, 2.1);
  absl::StatusOr<SimulationResult> r = Simulate(known, truth, Robot({0.4, 0.4, 0.0}));
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  EXPECT_EQ(r->num_small_obstacles, 1);
  EXPECT_THAT(r->obstacles_found, ::testing::ElementsAre(CellIndex{2, 5}));
  EXPECT_EQ(r->length_in_obstacles_m, 0.0);
  const Grid grid = testing::TrueGrid(truth);
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (grid.FromIndex(i) == CellIndex{2, 5}) continue;
    EXPECT_TRUE(r->swept[static_cast<size_t>(i)]) << "cell " << i << " is not swept";
  }
}

// The post stands in the only doorway to the second room: closing its cell
// would cut the room off, so the robot keeps the cell, sweeps the room and
// drives through the post (and says how far).
TEST(SmallObstacles, APostInTheOnlyDoorwayIsNotClosed) {
  OccupancyMap known = Open(7.2, 2.4);
  Block(&known, 3.2, 0.0, 4.0, 0.8);  // a wall at column 4, the doorway at row 1
  Block(&known, 3.2, 1.6, 4.0, 2.4);
  OccupancyMap truth = known;
  Block(&truth, 3.5, 1.1, 3.7, 1.3);  // on the doorway cell's centre (3.6, 1.2)
  absl::StatusOr<SimulationResult> r = Simulate(known, truth, Robot({1.2, 1.2, 0.0}));
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  EXPECT_EQ(r->num_small_obstacles, 0);
  EXPECT_THAT(r->obstacles_found, ::testing::IsEmpty());
  EXPECT_GT(r->length_in_obstacles_m, 0.0);
  const Grid grid = testing::TrueGrid(truth);
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (!grid.free_flags()[static_cast<size_t>(i)]) continue;
    EXPECT_TRUE(r->swept[static_cast<size_t>(i)]) << "cell " << i << " is not swept";
  }
}

}  // namespace
}  // namespace covplan
