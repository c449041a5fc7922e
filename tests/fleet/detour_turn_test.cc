// The detour turning bound (detour_turn.h): never above the least turning
// of drive paths found by an independent search (8 headings between cell
// centres, diagonals only with all four edges around the corner open) on
// random grids with blocked cells and thin-wall barriers; and around a wall
// open at one end only it prices the way round that end.
#include <algorithm>
#include <cmath>
#include <queue>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "planner/fleet/detour_turn.h"
#include "planner/tour/robot_model.h"

namespace covplan {
namespace {

constexpr int kDr[8] = {0, 1, 1, 1, 0, -1, -1, -1};
constexpr int kDc[8] = {1, 1, 0, -1, -1, -1, 0, 1};

bool Step(const Grid& g, int r, int c, int k) {
  const int dr = kDr[k], dc = kDc[k];
  if (dr == 0 || dc == 0) return g.Passable(r, c, dr, dc);
  return g.Passable(r, c, 0, dc) && g.Passable(r, c + dc, dr, 0) && g.Passable(r, c, dr, 0) &&
         g.Passable(r + dr, c, 0, dc);
}

// The least total turning of a path of 8-connected steps between the
// centres of `from` and `to`, leaving heading ha and arriving heading hb.
double LeastTurning(const Grid& g, CellIndex from, double ha, CellIndex to, double hb) {
  const int64_t n = g.size();
  std::vector<double> cost(static_cast<size_t>(n) * 8, INFINITY);
  using Item = std::pair<double, int64_t>;  // state = cell * 8 + heading
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  double best = from.row == to.row && from.col == to.col ? HeadingChange(ha, hb) : INFINITY;
  auto relax = [&](int64_t state, double c) {
    if (c < cost[state]) cost[state] = c, open.push({c, state});
  };
  for (int k = 0; k < 8; ++k) {
    if (Step(g, from.row, from.col, k)) {
      const int64_t cell = g.Index(from.row + kDr[k], from.col + kDc[k]);
      relax(cell * 8 + k, HeadingChange(ha, std::atan2(kDr[k], kDc[k])));
    }
  }
  while (!open.empty()) {
    const auto [c, state] = open.top();
    open.pop();
    if (c > cost[state]) continue;
    const CellIndex at = g.FromIndex(state / 8);
    const double heading = std::atan2(kDr[state % 8], kDc[state % 8]);
    if (at.row == to.row && at.col == to.col) best = std::min(best, c + HeadingChange(heading, hb));
    for (int k = 0; k < 8; ++k) {
      if (!Step(g, at.row, at.col, k)) continue;
      const int64_t cell = g.Index(at.row + kDr[k], at.col + kDc[k]);
      relax(cell * 8 + k, c + HeadingChange(heading, std::atan2(kDr[k], kDc[k])));
    }
  }
  return best;
}

TEST(DetourTurnBound, NeverAboveTheTurningOfARealPath) {
  std::mt19937 rng(11);
  std::bernoulli_distribution blocked(0.2), barrier(0.3), right_angle(0.7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  int positive = 0, checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int rows = 9, cols = 9;
    std::vector<uint8_t> free(rows * cols), walls(free.size());
    for (size_t i = 0; i < free.size(); ++i) {
      free[i] = !blocked(rng);
      walls[i] = static_cast<uint8_t>((barrier(rng) ? Grid::kWallRight : 0) |
                                      (barrier(rng) ? Grid::kWallUp : 0));
    }
    const Grid g(rows, cols, 0.8, {0.0, 0.0}, free, walls);
    std::uniform_int_distribution<int> cell(0, rows * cols - 1);
    for (int pair = 0; pair < 20; ++pair) {
      const CellIndex p = g.FromIndex(cell(rng)), q = g.FromIndex(cell(rng));
      if (!g.IsFree(p) || !g.IsFree(q)) continue;
      // Headings along the axes mostly (as ranks run), some at random.
      auto heading = [&] {
        return right_angle(rng) ? M_PI / 2 * std::uniform_int_distribution<int>(0, 3)(rng)
                                : angle(rng);
      };
      const double ha = heading(), hb = heading();
      const double real = LeastTurning(g, p, ha, q, hb);
      if (!std::isfinite(real)) continue;  // no path
      const double bound =
          DetourTurnBound(g, g.CellCenter(p), ha, g.CellCenter(q), hb, 12 * g.cell_size());
      EXPECT_LE(bound, real + 1e-9) << "trial " << trial << " (" << p.row << "," << p.col
                                    << ") -> (" << q.row << "," << q.col << ")";
      ++checked;
      positive += bound > 1e-6;
    }
  }
  EXPECT_GT(checked, 200);
  EXPECT_GT(positive, 20);  // the bound does find detours
}

// A move that clips the corner of a blocked cell with free cells beside it:
// the blocked stretch of the crossing line is almost nothing, and the bound
// stays below a legal path that slips past the corner.
TEST(DetourTurnBound, ClippingACornerCostsAlmostNothing) {
  const Grid g = Grid::FromAscii({"...", ".#."}, 1.0);  // blocked: row 0, column 1
  for (double y : {0.999, 0.95}) {
    const Point2 a{0.5, y}, b{2.5, y};
    // a -> the blocked cell's two top corners -> b, all on free squares.
    const std::vector<Point2> path = {a, {1.0, 1.0}, {2.0, 1.0}, b};
    double turning = 0.0, heading = 0.0;
    for (size_t i = 1; i < path.size(); ++i) {
      const double h = std::atan2(path[i].y - path[i - 1].y, path[i].x - path[i - 1].x);
      turning += HeadingChange(heading, h);
      heading = h;
    }
    turning += HeadingChange(heading, 0.0);
    EXPECT_LE(DetourTurnBound(g, a, 0.0, b, 0.0, 12.0), turning + 1e-9) << "y = " << y;
  }
}

TEST(DetourTurnBound, PricesTheWayRoundAWallOpenAtOneEnd) {
  // 5 x 5 free cells; a barrier above row 2 from column 2 to the east edge.
  // From (2, 2) heading east to (3, 2) heading west the robot must go round
  // the wall's west end: through its corner the headings 135 and 45 degrees
  // are driven, 135 + 90 + 135 degrees of turning, a full turn.
  std::vector<uint8_t> free(25, 1), walls(25, 0);
  for (int c = 2; c < 5; ++c) walls[2 * 5 + c] |= Grid::kWallUp;
  const Grid g(5, 5, 1.0, {0.0, 0.0}, free, walls);
  const double bound = DetourTurnBound(g, g.CellCenter(2, 2), 0.0, g.CellCenter(3, 2), M_PI, 12.0);
  EXPECT_GT(bound, M_PI * 1.9);  // the sampling margin takes a few degrees
  EXPECT_LE(bound, LeastTurning(g, {2, 2}, 0.0, {3, 2}, M_PI));
  // With the wall open at both ends the U-turn round the east end is free.
  std::vector<uint8_t> short_walls(25, 0);
  short_walls[2 * 5 + 2] |= Grid::kWallUp;
  const Grid open(5, 5, 1.0, {0.0, 0.0}, free, short_walls);
  EXPECT_LT(DetourTurnBound(open, open.CellCenter(2, 2), 0.0, open.CellCenter(3, 2), M_PI, 12.0),
            M_PI + 1e-9);
}

}  // namespace
}  // namespace covplan
