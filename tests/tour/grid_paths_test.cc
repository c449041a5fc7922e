#include "planner/tour/grid_paths.h"

#include <algorithm>
#include <cmath>
#include <random>

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

// A 40 x 40 px map at 0.1 m/px, tool 1 m (10 px per cell): free except a
// 0.3 m table at pixels 21..23 (rows and cols), inside cell (2, 2) and away
// from every line between 4-adjacent centres, so the cell stays free with no
// barrier around it.
OccupancyMap MapWithSmallTable() {
  OccupancyMap map(40, 40, 0.1, {0.0, 0.0});
  for (int r = 0; r < 40; ++r) {
    for (int c = 0; c < 40; ++c) {
      const bool table = r >= 21 && r <= 23 && c >= 21 && c <= 23;
      map.set(r, c, table ? CellState::kOccupied : CellState::kFree);
    }
  }
  return map;
}

TEST(LineOfSight, SmallObstacleInsideAFreeCellBlocksTheLineThroughIt) {
  GridOptions opt;
  opt.cell_size = 1.0;
  absl::StatusOr<Grid> g = BuildGrid(MapWithSmallTable(), opt);
  ASSERT_TRUE(g.ok()) << g.status();
  ASSERT_NE(g->obstacle_pixels(), nullptr);
  EXPECT_TRUE(g->IsFree(2, 2));
  EXPECT_EQ(g->CountBarriers(), 0);
  // (1,1) -> (3,3) runs through (2.2, 2.2) m: the table.
  EXPECT_FALSE(LineOfSight(*g, {1, 1}, {3, 3}));
  EXPECT_FALSE(LineOfSight(*g, {3, 3}, {1, 1}));
  // The same free cells without the pixels cannot see the table.
  const Grid cells_only(g->rows(), g->cols(), g->cell_size(), g->origin(), g->free_flags(),
                        g->walls());
  EXPECT_TRUE(LineOfSight(cells_only, {1, 1}, {3, 3}));
  // Lines that miss it stay open: along row 2 and column 2 (centre lines),
  // and diagonals elsewhere.
  EXPECT_TRUE(LineOfSight(*g, {2, 0}, {2, 3}));
  EXPECT_TRUE(LineOfSight(*g, {0, 2}, {3, 2}));
  EXPECT_TRUE(LineOfSight(*g, {1, 2}, {2, 3}));
  EXPECT_TRUE(LineOfSight(*g, {0, 3}, {3, 0}));

  // The any-angle path from (1,1) to (3,3) goes around the table and is
  // still close to the straight line's length.
  AnyAngleSearch search(*g);
  ASSERT_TRUE(search.Run({1, 1}, StopToken()));
  const std::vector<CellIndex> path = search.PathTo({3, 3});
  ASSERT_GE(path.size(), 3u);
  double len = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    EXPECT_TRUE(LineOfSight(*g, path[i - 1], path[i]));
    len += std::hypot(path[i].row - path[i - 1].row, path[i].col - path[i - 1].col);
  }
  EXPECT_GT(len, 2.0 * std::sqrt(2.0) + 1e-6);
  EXPECT_LT(len, 3.5);
}

// A pose in a blocked cell joins the grid at the nearest free neighbour its
// straight move reaches without cutting another blocked cell's corner.
TEST(JoinCell, AMoveOutOfABlockedCellCutsNoCorner) {
  Grid g = Grid::FromAscii({
      "#..",
      "##.",
      "...",
  });
  // Rows count from the bottom: the pose's cell (1, 0) is blocked; (2, 0)
  // and (1, 1) are blocked too. The pose sits near the top-right corner of
  // its cell, so the diagonal neighbour (2, 1)'s centre is nearest, but
  // that move would cut the corner between (2, 0) and (1, 1). Of the other
  // free neighbours (0, 0) and (0, 1), (0, 0) is nearer and reached cleanly.
  absl::StatusOr<CellIndex> c = JoinCell(g, Pose2{0.9, 1.9, 0.0}, "start");
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(*c, (CellIndex{0, 0}));
  // A free own cell is its own join cell; nothing free around is InvalidArgument.
  EXPECT_EQ(*JoinCell(g, Pose2{2.5, 0.5, 0.0}, "start"), (CellIndex{0, 2}));
  Grid walled = Grid::FromAscii({"###", "###", "###"});
  EXPECT_EQ(JoinCell(walled, Pose2{1.5, 1.5, 0.0}, "end").status().code(),
            absl::StatusCode::kInvalidArgument);
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
  // Must go round the wall (rows 1..3 at col 4): longer than 9, far shorter than a 4-connected
  // detour.
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
      for (const CellIndex& p : path)
        wps.push_back({g.CellCenter(p).x, g.CellCenter(p).y, 0, SegmentKind::kTransition, -1});
      ASSERT_EQ(testing::CheckPathStaysFree(g, wps), "") << "seed " << seed;
    }
  }
}

std::vector<CellIndex> FreeCells(const Grid& g) {
  std::vector<CellIndex> cells;
  for (int64_t i = 0; i < g.size(); ++i) {
    if (g.free_flags()[i]) cells.push_back(g.FromIndex(i));
  }
  return cells;
}

// A goal search capped at a few expansions and then asked again for the same
// pair goes on where it stopped: its distance and path are those of one
// uninterrupted search.
TEST(AnyAngleSearch, CappedRunToResumesAsOneSearch) {
  for (uint32_t seed = 0; seed < 10; ++seed) {
    const Grid g = testing::RandomGrid(30, 40, 0.75, seed);
    const std::vector<CellIndex> free_cells = FreeCells(g);
    AnyAngleSearch fresh(g), capped(g);
    std::mt19937 rng(seed);
    int resumed = 0;
    for (int k = 0; k < 40; ++k) {
      const CellIndex a = free_cells[rng() % free_cells.size()],
                      b = free_cells[rng() % free_cells.size()];
      ASSERT_TRUE(fresh.RunTo(a, b, StopToken()));
      float bound = -1.0f;
      if (capped.RunTo(a, b, StopToken(), 25, &bound)) {
        EXPECT_FLOAT_EQ(capped.DistanceCells(b), fresh.DistanceCells(b));
        continue;
      }
      ++resumed;
      EXPECT_GT(bound, 0.0f);
      ASSERT_TRUE(capped.RunTo(a, b, StopToken()));
      ASSERT_EQ(capped.Reached(b), fresh.Reached(b)) << "seed " << seed;
      if (!fresh.Reached(b)) continue;
      EXPECT_EQ(capped.DistanceCells(b), fresh.DistanceCells(b)) << "seed " << seed;
      const std::vector<CellIndex> p1 = capped.PathTo(b), p2 = fresh.PathTo(b);
      ASSERT_EQ(p1.size(), p2.size());
      for (size_t i = 0; i < p1.size(); ++i) EXPECT_EQ(p1[i], p2[i]);
    }
    EXPECT_GT(resumed, 0) << "seed " << seed;
  }
}

// Every cell a goal search closed on its way has its final path: legs in line
// of sight, lengths adding up to its distance (what the sparse tour harvests).
TEST(AnyAngleSearch, CellsClosedOnTheWayHaveTheirPaths) {
  for (uint32_t seed = 0; seed < 10; ++seed) {
    const Grid g = testing::RandomGrid(30, 40, 0.75, seed);
    const std::vector<CellIndex> free_cells = FreeCells(g);
    std::mt19937 rng(seed);
    AnyAngleSearch search(g);
    const CellIndex a = free_cells[rng() % free_cells.size()],
                    b = free_cells[rng() % free_cells.size()];
    ASSERT_TRUE(search.RunTo(a, b, StopToken()));
    int64_t closed = 0;
    search.ForEachClosed([&](int64_t i) {
      ++closed;
      const CellIndex c = g.FromIndex(i);
      const std::vector<CellIndex> path = search.PathTo(c);
      ASSERT_FALSE(path.empty());
      EXPECT_EQ(path.front(), a);
      EXPECT_EQ(path.back(), c);
      double len = 0.0;
      for (size_t k = 1; k < path.size(); ++k) {
        ASSERT_TRUE(LineOfSight(g, path[k - 1], path[k])) << "seed " << seed;
        len += std::hypot(path[k].row - path[k - 1].row, path[k].col - path[k - 1].col);
      }
      EXPECT_NEAR(len, search.DistanceCells(c), 1e-3 * (1.0 + len));
    });
    if (search.Reached(b)) {
      EXPECT_GE(closed, 1);
    }
  }
}

// The searches' own line-of-sight walk (move masks) agrees with LineOfSight
// on every pair of cells of maps with thin walls (barriers), small obstacles
// inside free cells (pixels) and blocked cells.
TEST(AnyAngleSearch, VisibleAgreesWithLineOfSight) {
  for (uint32_t seed = 0; seed < 6; ++seed) {
    std::mt19937 rng(seed);
    OccupancyMap map(60, 48, 0.1, {0.0, 0.0});
    for (int r = 0; r < map.height(); ++r) {
      for (int c = 0; c < map.width(); ++c) map.set(r, c, CellState::kFree);
    }
    for (int k = 0; k < 25; ++k) {  // specks and small blocks
      const int r0 = static_cast<int>(rng() % map.height()),
                c0 = static_cast<int>(rng() % map.width());
      const int h = 1 + static_cast<int>(rng() % 8), w = 1 + static_cast<int>(rng() % 8);
      for (int r = r0; r < std::min(map.height(), r0 + h); ++r) {
        for (int c = c0; c < std::min(map.width(), c0 + w); ++c)
          map.set(r, c, CellState::kOccupied);
      }
    }
    for (int k = 0; k < 3; ++k) {  // one-pixel walls with a gap: barriers between free cells
      const int c = 5 + static_cast<int>(rng() % (map.width() - 10));
      const int gap = static_cast<int>(rng() % map.height());
      for (int r = 0; r < map.height(); ++r) {
        if (std::abs(r - gap) > 4) map.set(r, c, CellState::kOccupied);
      }
    }
    GridOptions opt;
    opt.cell_size = 0.4;
    absl::StatusOr<Grid> g = BuildGrid(map, opt);
    ASSERT_TRUE(g.ok()) << g.status();
    ASSERT_NE(g->obstacle_pixels(), nullptr);
    AnyAngleSearch search(*g);
    int64_t visible = 0, hidden = 0;
    for (int64_t a = 0; a < g->size(); ++a) {
      for (int64_t b = 0; b < g->size(); ++b) {
        const CellIndex ca = g->FromIndex(a), cb = g->FromIndex(b);
        const bool los = LineOfSight(*g, ca, cb);
        ASSERT_EQ(search.Visible(ca, cb), los) << "seed " << seed << " (" << ca.row << "," << ca.col
                                               << ") -> (" << cb.row << "," << cb.col << ")";
        (los ? visible : hidden) += 1;
      }
    }
    EXPECT_GT(visible, 0);
    EXPECT_GT(hidden, 0);
    EXPECT_GT(g->CountBarriers(), 0) << "seed " << seed;
  }
}

}  // namespace
}  // namespace covplan
