// ObstaclePixels against brute force: on random maps, a segment is reported
// blocked when it enters a non-free pixel and clear when it stays away from
// every one; a mere touch of a corner or edge (up to rounding) may go either way.
#include "planner/grid/obstacle_pixels.h"

#include <cmath>
#include <random>

#include "gtest/gtest.h"

namespace covplan {
namespace {

// Brute force: does the closed segment (pixel units) meet the square of any
// non-free or off-map pixel grown by `margin` (negative: shrunk)? Separating
// axis test of a segment against an axis-aligned box.
bool BruteForceBlocked(const OccupancyMap& map, double x0, double y0, double x1, double y1,
                       double margin) {
  auto meets = [&](int i, int j) {
    const double lo_x = i - margin, hi_x = i + 1.0 + margin, lo_y = j - margin,
                 hi_y = j + 1.0 + margin;
    if (std::max(x0, x1) < lo_x || std::min(x0, x1) > hi_x) return false;
    if (std::max(y0, y1) < lo_y || std::min(y0, y1) > hi_y) return false;
    // The box's corners must not all lie strictly on one side of the line.
    const double nx = y1 - y0, ny = x0 - x1;
    int pos = 0, neg = 0;
    for (double cx : {lo_x, hi_x}) {
      for (double cy : {lo_y, hi_y}) {
        const double v = nx * (cx - x0) + ny * (cy - y0);
        pos += v > 0.0, neg += v < 0.0;
      }
    }
    return pos != 4 && neg != 4;
  };
  const int i_lo = static_cast<int>(std::floor(std::min(x0, x1))) - 1;
  const int i_hi = static_cast<int>(std::ceil(std::max(x0, x1)));
  const int j_lo = static_cast<int>(std::floor(std::min(y0, y1))) - 1;
  const int j_hi = static_cast<int>(std::ceil(std::max(y0, y1)));
  for (int j = j_lo; j <= j_hi; ++j) {
    for (int i = i_lo; i <= i_hi; ++i) {
      const bool off = i < 0 || j < 0 || i >= map.width() || j >= map.height();
      if ((off || !map.IsFree(j, i)) && meets(i, j)) return true;
    }
  }
  return false;
}

TEST(ObstaclePixels, SegmentBlockedMatchesBruteForceOnRandomMaps) {
  std::mt19937 rng(7);
  int checked_enters = 0, checked_clear = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const double s = std::uniform_int_distribution<int>(0, 1)(rng) ? 4.0 : 5.0;  // px per cell
    const int rows = 6, cols = 7;
    OccupancyMap map(static_cast<int>(cols * s), static_cast<int>(rows * s), 0.1, {0.0, 0.0});
    std::bernoulli_distribution blocked(0.04);
    for (int j = 0; j < map.height(); ++j) {
      for (int i = 0; i < map.width(); ++i) {
        map.set(j, i, blocked(rng) ? CellState::kOccupied : CellState::kFree);
      }
    }
    ObstaclePixels px(map, s, rows, cols);
    std::uniform_int_distribution<int> r_d(1, rows - 2), c_d(1, cols - 2);
    for (int k = 0; k < 200; ++k) {
      // Between cell centres (the only segments planners ask about) ...
      const Point2 a{c_d(rng) + 0.5, r_d(rng) + 0.5}, b{c_d(rng) + 0.5, r_d(rng) + 0.5};
      const bool enters = BruteForceBlocked(map, a.x * s, a.y * s, b.x * s, b.y * s, -1e-9);
      const bool near = BruteForceBlocked(map, a.x * s, a.y * s, b.x * s, b.y * s, 1e-9);
      auto check = [&](bool got) {
        if (enters) return got;
        if (!near) return !got;
        return true;
      };
      ASSERT_TRUE(check(px.SegmentBlocked(a, b)))
          << a.x << "," << a.y << " -> " << b.x << "," << b.y;
      // ... and, cell by cell, the per-cell check agrees with the whole.
      bool any = false;
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c)
          any |= px.CellDirty(r, c) && px.SegmentBlockedInCell(r, c, a, b);
      }
      ASSERT_TRUE(check(any)) << a.x << "," << a.y << " -> " << b.x << "," << b.y;
      checked_enters += enters;
      checked_clear += !near;
    }
    // Diagonal steps are precomputed consistently.
    for (int r = 0; r + 1 < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        for (int dc : {-1, 1}) {
          if (c + dc < 0 || c + dc >= cols) continue;
          const bool seg = px.SegmentBlocked({c + 0.5, r + 0.5}, {c + dc + 0.5, r + 1.5});
          ASSERT_EQ(px.DiagonalBlocked(r, c, 1, dc), seg);
          ASSERT_EQ(px.DiagonalBlocked(r + 1, c + dc, -1, -dc), seg);
        }
      }
    }
  }
  // Both outcomes were exercised many times.
  EXPECT_GT(checked_enters, 1000);
  EXPECT_GT(checked_clear, 1000);
}

TEST(ObstaclePixels, CellsTouchingTheMapEdgeAreDirty) {
  OccupancyMap map(20, 20, 0.1, {0.0, 0.0});
  for (int j = 0; j < 20; ++j) {
    for (int i = 0; i < 20; ++i) map.set(j, i, CellState::kFree);
  }
  ObstaclePixels px(map, 5.0, 4, 4);
  EXPECT_TRUE(px.CellDirty(0, 2));
  EXPECT_TRUE(px.CellDirty(3, 1));
  EXPECT_FALSE(px.CellDirty(1, 1));
  EXPECT_FALSE(px.CellDirty(2, 2));
  EXPECT_FALSE(px.SegmentBlocked({1.5, 1.5}, {2.5, 2.5}));
  EXPECT_TRUE(px.SegmentBlocked({1.5, 1.5}, {1.5, -0.5}));
}

}  // namespace
}  // namespace covplan
