// The makespan bound's geodesic moves (geodesic.h, docs/fleet.md): the hop
// bound (D - 1) h never exceeds the length of a drive path found by
// independent searches on random grids with walls and thin-wall barriers;
// and on two rooms joined by a far door the bound with the wall is above the
// straight-line bound and below the real plans.
#include <algorithm>
#include <cmath>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "planner/fleet/bounds.h"
#include "planner/fleet/geodesic.h"
#include "planner/tour/grid_paths.h"
#include "tests/fleet/fleet_fixtures.h"

namespace covplan {
namespace {

struct Trial {
  Point2 p, q;
  CellIndex pc, qc;  // the free cells the paths run between
};

// Random free cells, blocked cells and barriers (row 0 = smallest y).
Grid RandomGrid(std::mt19937& rng, int rows, int cols, double cell) {
  std::bernoulli_distribution blocked(0.2), barrier(0.25);
  std::vector<uint8_t> free(static_cast<size_t>(rows) * cols), walls(free.size());
  for (size_t i = 0; i < free.size(); ++i) {
    free[i] = !blocked(rng);
    walls[i] = static_cast<uint8_t>((barrier(rng) ? Grid::kWallRight : 0) |
                                    (barrier(rng) ? Grid::kWallUp : 0));
  }
  return Grid(rows, cols, cell, {0.0, 0.0}, free, walls);
}

// Shortest paths between cell centres: 4-steps through passable edges and
// diagonals with all four edges around the corner open (no corner cutting).
struct CentrePaths {
  std::vector<double> dist;
  std::vector<int64_t> parent;
};

CentrePaths CentreDijkstra(const Grid& g, CellIndex from) {
  CentrePaths out{std::vector<double>(static_cast<size_t>(g.size()), INFINITY),
                  std::vector<int64_t>(static_cast<size_t>(g.size()), -1)};
  using Item = std::pair<double, int64_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  out.dist[g.Index(from.row, from.col)] = 0.0;
  open.push({0.0, g.Index(from.row, from.col)});
  while (!open.empty()) {
    const auto [du, u] = open.top();
    open.pop();
    if (du > out.dist[u]) continue;
    const CellIndex c = g.FromIndex(u);
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        if (dr == 0 && dc == 0) continue;
        bool ok;
        if (dr == 0 || dc == 0) {
          ok = g.Passable(c.row, c.col, dr, dc);
        } else {
          ok = g.Passable(c.row, c.col, 0, dc) && g.Passable(c.row, c.col + dc, dr, 0) &&
               g.Passable(c.row, c.col, dr, 0) && g.Passable(c.row + dr, c.col, 0, dc);
        }
        if (!ok) continue;
        const int64_t v = g.Index(c.row + dr, c.col + dc);
        const double dv = du + g.cell_size() * std::hypot(dr, dc);
        if (dv < out.dist[v]) {
          out.dist[v] = dv;
          out.parent[v] = u;
          open.push({dv, v});
        }
      }
    }
  }
  return out;
}

// The path p -> centres -> q that CentreDijkstra found.
std::vector<Waypoint> CentrePath(const Grid& g, const CentrePaths& paths, Point2 p, Point2 q,
                                 CellIndex qc) {
  std::vector<Waypoint> back = {{q.x, q.y, 0.0, SegmentKind::kTransition, -1}};
  for (int64_t v = g.Index(qc.row, qc.col); v >= 0; v = paths.parent[v]) {
    const Point2 c = g.CellCenter(g.FromIndex(v));
    back.push_back({c.x, c.y, 0.0, SegmentKind::kTransition, -1});
  }
  back.push_back({p.x, p.y, 0.0, SegmentKind::kStart, -1});
  return {back.rbegin(), back.rend()};
}

// Shortest any-angle path between cell centres over the planner's
// line-of-sight rule (a visibility graph, Floyd-Warshall): shorter than the
// 8-connected one, so a sharper test of the bound.
std::vector<double> VisibilityDistances(const Grid& g) {
  const int64_t n = g.size();
  std::vector<double> d(static_cast<size_t>(n * n), INFINITY);
  for (int64_t a = 0; a < n; ++a) {
    for (int64_t b = 0; b < n; ++b) {
      if (a == b && g.free_flags()[a]) {
        d[a * n + b] = 0.0;
      } else if (g.free_flags()[a] && g.free_flags()[b] &&
                 LineOfSight(g, g.FromIndex(a), g.FromIndex(b))) {
        const Point2 pa = g.CellCenter(g.FromIndex(a)), pb = g.CellCenter(g.FromIndex(b));
        d[a * n + b] = std::hypot(pa.x - pb.x, pa.y - pb.y);
      }
    }
  }
  for (int64_t m = 0; m < n; ++m) {
    for (int64_t a = 0; a < n; ++a) {
      for (int64_t b = 0; b < n; ++b)
        d[a * n + b] = std::min(d[a * n + b], d[a * n + m] + d[m * n + b]);
    }
  }
  return d;
}

// A random point in a random free cell, or (a dock) in a blocked cell with
// a free 8-neighbour, which the path then joins first.
bool RandomPoint(std::mt19937& rng, const Grid& g, Point2* p, CellIndex* join) {
  std::uniform_int_distribution<int> row(0, g.rows() - 1), col(0, g.cols() - 1);
  std::uniform_real_distribution<double> frac(0.0, 1.0);
  const CellIndex c{row(rng), col(rng)};
  *p = {(c.col + frac(rng)) * g.cell_size(), (c.row + frac(rng)) * g.cell_size()};
  if (g.IsFree(c)) {
    *join = c;
    return true;
  }
  for (int dr = -1; dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      if (g.IsFree(c.row + dr, c.col + dc)) {
        *join = {c.row + dr, c.col + dc};
        return true;
      }
    }
  }
  return false;
}

TEST(GeodesicHops, NeverAboveTheShortestDrivePathOnRandomGridsWithBarriers) {
  std::mt19937 rng(11);
  int above_line = 0, pairs = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Grid g = RandomGrid(rng, 7 + trial % 5, 8 + trial % 4, 0.5);
    std::vector<Trial> trials;
    std::vector<Point2> points;
    for (int i = 0; i < 12; ++i) {
      Trial t;
      if (!RandomPoint(rng, g, &t.p, &t.pc) || !RandomPoint(rng, g, &t.q, &t.qc)) continue;
      trials.push_back(t);
      points.push_back(t.p);
      points.push_back(t.q);
    }
    const std::vector<double> vis = VisibilityDistances(g);
    // The drive grid's own cells, and blocks of 2 x 2 and 3 x 3 cells.
    for (const int64_t max_squares : {g.size(), g.size() / 4, g.size() / 9}) {
      GeodesicHops geo(g, points, max_squares);
      for (size_t i = 0; i < trials.size(); ++i) {
        const Trial& t = trials[i];
        const CentrePaths cells = CentreDijkstra(g, t.pc);
        const int64_t qi = g.Index(t.qc.row, t.qc.col);
        const double via = vis[g.Index(t.pc.row, t.pc.col) * g.size() + qi];
        const double inner = std::min(cells.dist[qi], via);
        if (!std::isfinite(inner)) continue;  // no path: any bound holds
        const Point2 pc = g.CellCenter(t.pc), qc = g.CellCenter(t.qc);
        const double path =
            std::hypot(t.p.x - pc.x, t.p.y - pc.y) + inner + std::hypot(t.q.x - qc.x, t.q.y - qc.y);
        // The 8-connected path is one the conformance checks accept.
        if (trial % 10 == 0 && g.IsFree(g.CellAt(t.p)) && g.IsFree(g.CellAt(t.q)) &&
            std::isfinite(cells.dist[qi])) {
          EXPECT_EQ(testing::CheckPathStaysFree(g, CentrePath(g, cells, t.p, t.q, t.qc)), "");
        }
        geo.Search(static_cast<int>(2 * i), -1);
        const double bound = geo.MinLength(geo.Hops(static_cast<int>(2 * i + 1)));
        EXPECT_LE(bound, path + 1e-9)
            << "trial " << trial << " pair " << i << " factor " << geo.factor();
        // Searched the other way, and cut short: never more.
        geo.Search(static_cast<int>(2 * i + 1), 2);
        EXPECT_LE(geo.MinLength(geo.Hops(static_cast<int>(2 * i))), path + 1e-9);
        ++pairs;
        if (bound > std::hypot(t.q.x - t.p.x, t.q.y - t.p.y) + 1e-9) ++above_line;
      }
    }
  }
  // The walls matter: many pairs are bounded above their straight line.
  EXPECT_GT(pairs, 1000);
  EXPECT_GT(above_line, pairs / 100);
}

// Two rooms side by side, 5.6 m x 4 m each (7 x 5 cells of 0.8 m), joined by
// a door in the top row of cells. The wall between them is a column of
// blocked cells (`thin` false) or 3 pixels on the cells' border, which the
// grid keeps as barriers. The cheapest ways into a room's ranks in
// straight lines run on through the wall, with no U-turn.
OccupancyMap TwoRooms(bool thin) {
  const double res = 0.05;
  const int border = 16, room_w = 112, room_h = 80, wall_w = thin ? 0 : 16;  // pixels
  const int w = 2 * border + 2 * room_w + wall_w, h = 2 * border + room_h;
  const int wall0 = thin ? border + room_w - 1 : border + room_w;
  const int wall1 = thin ? wall0 + 3 : wall0 + wall_w;
  OccupancyMap map(w, h, res, {0.0, 0.0});
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const bool outer = r < border || r >= h - border || c < border || c >= w - border;
      const bool wall = c >= wall0 && c < wall1 && r < border + room_h - 16;
      map.set(r, c, outer || wall ? CellState::kOccupied : CellState::kFree);
    }
  }
  return map;
}

FleetRequest RoomsFleet(int k) {
  FleetRequest f;
  f.base.planner = "oarp";
  f.base.common.time_limit_s = 0.5;
  f.base.common.robot.tool_width_m = 0.8;
  // Docks at the south ends of both rooms, far from the door.
  const double xs[3] = {1.2, 11.2, 4.0};
  for (int r = 0; r < k; ++r) {
    f.robots.push_back(testing::Robot("r" + std::to_string(r), 0.8, xs[r], 1.2));
  }
  return f;
}

TEST(MakespanLowerBound, AWallRaisesTheBoundAboveTheStraightLinesAndBelowTheSingleRobotPlan) {
  const PlannerRegistry registry = BuiltinPlanners();
  for (const bool thin : {false, true}) {
    SCOPED_TRACE(thin ? "thin wall" : "wall of cells");
    const OccupancyMap map = TwoRooms(thin);
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, EngineLimits{});
    const FleetRequest f = RoomsFleet(1);
    absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, testing::SourceOfMap(map, "rooms"), f);
    ASSERT_TRUE(fleet.ok()) << fleet.status();
    const EngineResult& one = fleet->robots[0].result;
    if (thin) {
      EXPECT_GT(one.area->drive->CountBarriers(), 0) << "the thin wall is no barrier";
    }
    const TourUnits units = UnitsOfPlan(one.plan, *one.area->cover);
    const double line = MakespanLowerBound(units, f.robots, nullptr).value();
    const double geodesic = MakespanLowerBound(units, f.robots, one.area->drive.get()).value();
    EXPECT_EQ(geodesic, fleet->lower_bound_s);
    EXPECT_GT(geodesic, 1.02 * line);
    EXPECT_LE(geodesic, one.plan.stats.estimated_duration_s + 1e-6);
    EXPECT_LE(geodesic, fleet->makespan_s + 1e-6);
  }
}

TEST(MakespanLowerBound, WithTheWallItStaysBelowRealFleetPlans) {
  const PlannerRegistry registry = BuiltinPlanners();
  for (const bool thin : {false, true}) {
    const OccupancyMap map = TwoRooms(thin);
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, EngineLimits{});
    // One tour of the whole site, as the fleet's reference tour.
    absl::StatusOr<EngineResult> one =
        engine.Plan(testing::SourceOfMap(map, "rooms"), RoomsFleet(1).RobotRequest(0));
    ASSERT_TRUE(one.ok()) << one.status();
    const TourUnits units = UnitsOfPlan(one->plan, *one->area->cover);
    for (const int k : {2, 3}) {
      SCOPED_TRACE(absl::StrFormat("%s, k = %d", thin ? "thin wall" : "wall of cells", k));
      const FleetRequest f = RoomsFleet(k);
      absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, testing::SourceOfMap(map, "rooms"), f);
      ASSERT_TRUE(fleet.ok()) << fleet.status();
      absl::StatusOr<std::shared_ptr<const CoverageArea>> area =
          engine.AreaFor(testing::SourceOfMap(map, "rooms"), f.base);
      ASSERT_TRUE(area.ok()) << area.status();
      EXPECT_EQ(testing::CheckFleetPlan(*fleet, f, **area), "");
      EXPECT_GT(fleet->lower_bound_s, 0.0);
      EXPECT_LE(fleet->lower_bound_s, fleet->makespan_s + 1e-6);
      // On one tour's units, the wall raises the bound for k robots too.
      const double line = MakespanLowerBound(units, f.robots, nullptr).value();
      const double geodesic = MakespanLowerBound(units, f.robots, (*area)->drive.get()).value();
      EXPECT_GT(geodesic, line);
    }
  }
}

}  // namespace
}  // namespace covplan
