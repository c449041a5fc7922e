#include "planner/tour/grid_paths.h"

#include <cmath>

#include "gtest/gtest.h"
#include "tests/testing/grid_fixtures.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

TEST(LineOfSight, BlockedByObstacleAndCorners) {
  Grid g = Grid::FromAscii({
      "....",
      ".#..",
      "....",
  });
  // Rows count from the bottom: the '#' is at row 1, col 1.
  EXPECT_TRUE(LineOfSight(g, {0, 0}, {0, 3}));
  EXPECT_FALSE(LineOfSight(g, {1, 0}, {1, 3}));
  // Diagonal through the corner shared with the blocked cell.
  EXPECT_FALSE(LineOfSight(g, {0, 0}, {2, 2}));
  EXPECT_TRUE(LineOfSight(g, {0, 2}, {2, 3}));
  EXPECT_TRUE(LineOfSight(g, {2, 2}, {2, 2}));
}

TEST(LineOfSight, DiagonalSqueezeBetweenTwoBlocksIsRejected) {
  Grid g = Grid::FromAscii({
      ".#",
      "#.",
  });
  EXPECT_FALSE(LineOfSight(g, {0, 1}, {1, 0}));
}

TEST(AnyAngleSearch, PathAroundWallIsShortAndFree) {
  Grid g = Grid::FromAscii({
      "..........",
      "..........",
      "....#.....",
      "....#.....",
      "....#.....",
      "..........",
  });
  AnyAngleSearch search(g);
  ASSERT_TRUE(search.Run({3, 0}, StopToken()));
  std::vector<CellIndex> path = search.PathTo({3, 9});
  ASSERT_GE(path.size(), 3u);
  EXPECT_EQ(path.front(), (CellIndex{3, 0}));
  EXPECT_EQ(path.back(), (CellIndex{3, 9}));
  double length = 0.0;
  std::vector<Waypoint> wps;
  for (size_t i = 0; i < path.size(); ++i) {
    const Point2 p = g.CellCenter(path[i]);
    wps.push_back({p.x, p.y, 0.0, i ? SegmentKind::kTransition : SegmentKind::kStart, -1});
    if (i) length += std::hypot(path[i].row - path[i - 1].row, path[i].col - path[i - 1].col);
  }
  EXPECT_EQ(testing::CheckPathStaysFree(g, wps), "");
  EXPECT_NEAR(length, search.DistanceCells({3, 9}), 1e-4);
  // Must go round the wall (rows 1..3 at col 4): longer than 9, far shorter than a 4-connected detour.
  EXPECT_GT(length, 9.0);
  EXPECT_LT(length, 10.5);
}

TEST(AnyAngleSearch, UnreachableComponent) {
  Grid g = Grid::FromAscii({"..#.."});
  AnyAngleSearch search(g);
  ASSERT_TRUE(search.Run({0, 0}, StopToken()));
  EXPECT_TRUE(search.Reached({0, 1}));
  EXPECT_FALSE(search.Reached({0, 3}));
  EXPECT_TRUE(search.PathTo({0, 4}).empty());
  int32_t n = 0;
  FreeComponents(g, &n);
  EXPECT_EQ(n, 2);
}

TEST(AnyAngleSearch, RandomGridsPathsStayFree) {
  for (uint32_t seed = 0; seed < 20; ++seed) {
    Grid g = testing::RandomGrid(25, 30, 0.8, seed);
    int64_t src = -1;
    for (int64_t i = 0; i < g.size() && src < 0; ++i) {
      if (g.free_flags()[i]) src = i;
    }
    AnyAngleSearch search(g);
    ASSERT_TRUE(search.Run(g.FromIndex(src), StopToken()));
    for (int64_t i = 0; i < g.size(); ++i) {
      const CellIndex c = g.FromIndex(i);
      if (!search.Reached(c)) continue;
      std::vector<CellIndex> path = search.PathTo(c);
      for (size_t k = 1; k < path.size(); ++k) {
        ASSERT_TRUE(LineOfSight(g, path[k - 1], path[k])) << "seed " << seed;
      }
      std::vector<Waypoint> wps;
      for (const CellIndex& p : path) wps.push_back({g.CellCenter(p).x, g.CellCenter(p).y, 0, SegmentKind::kTransition, -1});
      ASSERT_EQ(testing::CheckPathStaysFree(g, wps), "") << "seed " << seed;
    }
  }
}

}  // namespace
}  // namespace covplan
