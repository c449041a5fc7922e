// The floor measure against geometry worked out by hand: a disc of radius r
// rolling inside a rectangle reaches all of it but the four corner fillets,
// (4 - pi) r^2; it goes around a convex no-go zone; it does not pass a door
// narrower than the tool; a straight path sweeps a stadium 2 r L + pi r^2.
// The disc test equals a brute-force one, the engine fills the statistics
// of every plan, and a recount from the pixels written apart from the
// engine's code gives the same figures.
#include "planner/plan/floor_measure.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/plan/svg.h"
#include "tests/fleet/fleet_fixtures.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

constexpr double kRes = 0.05;  // m per pixel
constexpr double kTool = 0.8;
constexpr double kR = kTool / 2;
const double kCornerLoss = (4.0 - M_PI) * kR * kR;
// The disc's centres sit on pixel centres, so in a corner it stays half a
// pixel further out than a continuous disc would: up to 4 ((r + res/2)^2 -
// pi r^2 / 4) - kCornerLoss = 0.08 m2 more is lost in a rectangle's corners.
constexpr double kPixelSlack = 0.12;

// A free rectangle of w x h metres (off the map is not free), with walls
// (rectangles in metres, x0 y0 x1 y1) drawn in.
OccupancyMap Room(double w, double h, const std::vector<std::vector<double>>& walls = {}) {
  OccupancyMap map(static_cast<int>(std::lround(w / kRes)), static_cast<int>(std::lround(h / kRes)),
                   kRes, {0.0, 0.0});
  for (int r = 0; r < map.height(); ++r) {
    for (int c = 0; c < map.width(); ++c) {
      const double x = (c + 0.5) * kRes, y = (r + 0.5) * kRes;
      bool wall = false;
      for (const auto& b : walls) wall = wall || (x > b[0] && x < b[2] && y > b[1] && y < b[3]);
      map.set(r, c, wall ? CellState::kOccupied : CellState::kFree);
    }
  }
  return map;
}

struct Site {
  OccupancyMap map;
  PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine{&registry, &cache, EngineLimits{}};
  std::shared_ptr<const CoverageArea> area;

  explicit Site(OccupancyMap m, std::vector<PolygonInput> no_go = {}) : map(std::move(m)) {
    PlanRequest r;
    r.common.robot.tool_width_m = kTool;
    r.no_go = std::move(no_go);
    absl::StatusOr<std::shared_ptr<const CoverageArea>> a =
        engine.AreaFor(testing::SourceOfMap(map, "room"), r);
    EXPECT_TRUE(a.ok()) << a.status();
    area = *a;
  }
  FloorReach Reach() const {
    return ComputeFloorReach(*area->drive, area->zones.no_go.get(), area->zones.regions.get());
  }
};

// The figures recounted from the map's pixels apart from the engine's code:
// a tool centre fits on a pixel centre when every closed pixel (not free, or
// off the map) in the square around it is at least r + 1/2 pixel away; the
// centres the robot reaches are flooded from those in its drive grid's free
// cells (the robot's connected part of the map); a pixel is
// reachable when free and within r of such a centre, swept when within r of
// a segment of the path (the exact distance, not the engine's stamps).
struct Recount {
  int64_t reachable_px = 0, swept_px = 0;
};

Recount RecountFromPixels(const OccupancyMap& map, const Grid& drive,
                          const std::vector<Waypoint>& path, double tool_width_m) {
  const int w = map.width(), h = map.height();
  // The radius in pixels as the grid's frame has it (0.8 m at 0.05 m/px: 8).
  const double res = map.resolution(), r = 0.5 * SnapToInteger(tool_width_m / res);
  auto closed = [&](int i, int j) {
    return i < 0 || j < 0 || i >= w || j >= h || !map.IsFree(j, i);
  };
  const int span = static_cast<int>(std::ceil(r + 0.5));
  std::vector<char> fits(static_cast<size_t>(w) * h, 0), centre(fits.size(), 0);
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      bool ok = true;
      for (int dj = -span; dj <= span && ok; ++dj) {
        for (int di = -span; di <= span && ok; ++di) {
          ok = !(di * di + dj * dj < (r + 0.5) * (r + 0.5) && closed(i + di, j + dj));
        }
      }
      fits[static_cast<size_t>(j) * w + i] = ok;
    }
  }
  std::vector<std::pair<int, int>> stack;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const CellIndex cell =
          drive.CellAt({map.origin().x + (i + 0.5) * res, map.origin().y + (j + 0.5) * res});
      if (fits[static_cast<size_t>(j) * w + i] && drive.IsFree(cell)) stack.push_back({i, j});
    }
  }
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (i < 0 || j < 0 || i >= w || j >= h) continue;
    const size_t at = static_cast<size_t>(j) * w + i;
    if (!fits[at] || centre[at]) continue;
    centre[at] = 1;
    for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
      stack.push_back({i + di, j + dj});
  }
  std::vector<char> swept(fits.size(), 0);
  for (size_t k = 1; k < path.size(); ++k) {
    const double ax = (path[k - 1].x - map.origin().x) / res - 0.5;
    const double ay = (path[k - 1].y - map.origin().y) / res - 0.5;
    const double bx = (path[k].x - map.origin().x) / res - 0.5;
    const double by = (path[k].y - map.origin().y) / res - 0.5;
    const double len2 = (bx - ax) * (bx - ax) + (by - ay) * (by - ay);
    for (int j = std::max(0, static_cast<int>(std::floor(std::min(ay, by) - r)));
         j <= std::min(h - 1, static_cast<int>(std::ceil(std::max(ay, by) + r))); ++j) {
      for (int i = std::max(0, static_cast<int>(std::floor(std::min(ax, bx) - r)));
           i <= std::min(w - 1, static_cast<int>(std::ceil(std::max(ax, bx) + r))); ++i) {
        const double t =
            len2 > 0.0 ? std::clamp(((i - ax) * (bx - ax) + (j - ay) * (by - ay)) / len2, 0.0, 1.0)
                       : 0.0;
        const double dx = i - (ax + t * (bx - ax)), dy = j - (ay + t * (by - ay));
        if (dx * dx + dy * dy <= r * r) swept[static_cast<size_t>(j) * w + i] = 1;
      }
    }
  }
  Recount out;
  const int reach = static_cast<int>(std::floor(r));
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      if (closed(i, j)) continue;
      bool touched = false;
      for (int dj = -reach; dj <= reach && !touched; ++dj) {
        for (int di = -reach; di <= reach && !touched; ++di) {
          const int ci = i + di, cj = j + dj;
          touched = di * di + dj * dj <= r * r && ci >= 0 && cj >= 0 && ci < w && cj < h &&
                    centre[static_cast<size_t>(cj) * w + ci];
        }
      }
      out.reachable_px += touched;
      out.swept_px += touched && swept[static_cast<size_t>(j) * w + i];
    }
  }
  return out;
}

double ReachableM2(const FloorReach& r) { return r.reachable_px * r.pixel_m * r.pixel_m; }

TEST(FloorMeasure, NearSitesIsExact) {
  std::mt19937 rng(7);
  const int64_t w = 37, h = 23;
  for (double radius2 : {0.0, 2.0, 8.5, 30.0, 72.25, 5000.0}) {
    for (unsigned one_in : {2u, 29u, 400u}) {
      std::vector<uint8_t> site(w * h, 0);
      for (uint8_t& s : site) s = rng() % one_in == 0;
      const std::vector<uint8_t> near = NearSites(site, w, h, radius2);
      for (int64_t p = 0; p < w * h; ++p) {
        bool want = false;
        for (int64_t q = 0; q < w * h && !want; ++q) {
          const double dx = p % w - q % w, dy = p / w - q / w;
          want = site[q] && dx * dx + dy * dy <= radius2;
        }
        ASSERT_EQ(near[p], want) << "pixel " << p << " radius2 " << radius2 << " 1/" << one_in;
      }
    }
  }
  // Fixed cases: no site at all, one row, one column, a lone corner site
  // reaching the far corner only with a large radius, a size mismatch.
  EXPECT_EQ(NearSites(std::vector<uint8_t>(12, 0), 4, 3, 100.0), std::vector<uint8_t>(12, 0));
  EXPECT_EQ(NearSites({0, 0, 1, 0, 0, 0, 0}, 7, 1, 4.0),
            (std::vector<uint8_t>{1, 1, 1, 1, 1, 0, 0}));
  EXPECT_EQ(NearSites({0, 0, 1, 0, 0, 0, 0}, 1, 7, 1.0),
            (std::vector<uint8_t>{0, 1, 1, 1, 0, 0, 0}));
  std::vector<uint8_t> corner(30 * 20, 0);
  corner[0] = 1;
  const double far2 = 29.0 * 29.0 + 19.0 * 19.0;
  EXPECT_EQ(NearSites(corner, 30, 20, far2 - 1.0).back(), 0);
  EXPECT_EQ(NearSites(corner, 30, 20, far2).back(), 1);
  EXPECT_EQ(NearSites(corner, 30, 21, far2), std::vector<uint8_t>(corner.size(), 0));
}

// Far and non-finite waypoints: a segment is clipped to the map before it is
// sampled, so a path to a point far off the map sweeps what a path to just
// past the map's edge sweeps, and a NaN waypoint's segments sweep nothing.
TEST(FloorMeasure, FarAndNonFiniteWaypointsAreClippedOrSkipped) {
  Site s(Room(10.0, 6.0));
  const FloorReach reach = s.Reach();
  auto swept = [&](std::vector<Waypoint> path) {
    return MeasureFloor(reach, path, false).swept_reachable_m2;
  };
  Waypoint a, near_edge, far, nan;
  a.x = 1.0, a.y = 3.0;
  near_edge.x = 12.0, near_edge.y = 3.0;
  far.x = 1e300, far.y = 3.0;
  nan.x = std::nan(""), nan.y = 3.0;
  EXPECT_GT(swept({a, near_edge}), 0.0);
  EXPECT_DOUBLE_EQ(swept({a, far}), swept({a, near_edge}));
  EXPECT_EQ(swept({a, nan}), 0.0);
  EXPECT_EQ(swept({nan}), 0.0);
  EXPECT_DOUBLE_EQ(swept({a, nan, a, near_edge}), swept({a, near_edge}));
}

TEST(FloorMeasure, ARoomIsReachableButItsCornerFillets) {
  Site s(Room(10.0, 6.0));
  const FloorReach r = s.Reach();
  EXPECT_NEAR(ReachableM2(r), 60.0 - kCornerLoss, kPixelSlack);
}

TEST(FloorMeasure, TheToolGoesAroundAConvexNoGoZone) {
  PolygonInput zone;
  zone.outer = {{4.5, 2.5}, {5.5, 2.5}, {5.5, 3.5}, {4.5, 3.5}, {4.5, 2.5}};
  Site s(Room(10.0, 6.0), {zone});
  EXPECT_NEAR(ReachableM2(s.Reach()), 60.0 - kCornerLoss - 1.0, kPixelSlack);
}

TEST(FloorMeasure, ADoorNarrowerThanTheToolClosesTheRoomBehindIt) {
  // A wall at x = 12..12.2 m with a door at y = 2..2.6 m (0.6 m < the tool);
  // the robot's part is the larger room, 12 m x 6 m.
  Site narrow(Room(19.2, 6.0, {{12.0, 0.0, 12.2, 2.0}, {12.0, 2.6, 12.2, 6.0}}));
  const double left = ReachableM2(narrow.Reach());
  EXPECT_GT(left, 72.0 - kCornerLoss - 2 * kPixelSlack);
  EXPECT_LT(left, 72.0 + 0.2);  // and a sliver of the doorway
  // A 1.2 m door lets the disc through: both rooms.
  Site wide(Room(19.2, 6.0, {{12.0, 0.0, 12.2, 2.0}, {12.0, 3.2, 12.2, 6.0}}));
  EXPECT_GT(ReachableM2(wide.Reach()), 72.0 + 42.0 - 4 * kCornerLoss - 0.2);
}

TEST(FloorMeasure, AStraightPathSweepsAStadium) {
  Site s(Room(10.0, 6.0));
  const FloorReach reach = s.Reach();
  std::vector<Waypoint> path(2);
  path[0].x = 2.0, path[0].y = 3.0;
  path[1].x = 8.0, path[1].y = 3.0;
  const FloorMeasure m = MeasureFloor(reach, path, /*keep_missed=*/true);
  const double stadium = 2 * kR * 6.0 + M_PI * kR * kR;
  EXPECT_NEAR(m.swept_reachable_m2, stadium, 0.02);
  EXPECT_NEAR(m.reachable_area_m2, ReachableM2(reach), 1e-9);
  EXPECT_NEAR(m.missed_reachable_m2, m.reachable_area_m2 - m.swept_reachable_m2, 1e-9);
  EXPECT_NEAR(m.swept_reachable_ratio, m.swept_reachable_m2 / m.reachable_area_m2, 1e-12);
  int64_t missed = 0;
  for (uint8_t f : m.missed) missed += f;
  EXPECT_NEAR(missed * kRes * kRes, m.missed_reachable_m2, 1e-9);
}

TEST(FloorMeasure, APixelRecountGivesTheEnginesFigures) {
  Site site(testing::LoadShippedMap("sample_office.yaml"));
  PlanRequest r;
  r.common.robot.tool_width_m = kTool;
  absl::StatusOr<EngineResult> plan = site.engine.Plan(testing::SourceOfMap(site.map, "room"), r);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const PlanStats& s = plan->plan.stats;
  const OccupancyMap& map = site.map;
  const Recount n = RecountFromPixels(map, *plan->area->drive, plan->plan.path, kTool);
  const double px_m2 = map.resolution() * map.resolution();
  ASSERT_GT(n.reachable_px, 0);
  EXPECT_NEAR(s.reachable_area_m2, n.reachable_px * px_m2, 1e-6);
  // The engine stamps discs every half pixel along a segment: at a radius of
  // 8 pixels their union lies within 0.004 pixel of the exact stadium.
  EXPECT_NEAR(s.swept_reachable_ratio,
              static_cast<double>(n.swept_px) / static_cast<double>(n.reachable_px), 1e-3);
  EXPECT_NEAR(s.missed_reachable_m2, (n.reachable_px - n.swept_px) * px_m2, 0.05);
}

TEST(FloorMeasure, EveryPlanCarriesTheMeasure) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  PlanOptions o;
  o.robot.tool_width_m = kTool;
  absl::StatusOr<CoveragePlan> plan = PlanCoverage(map, o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const PlanStats& s = plan->stats;
  EXPECT_GT(s.reachable_area_m2, 0.0);
  EXPECT_LE(s.reachable_area_m2, s.map_free_area_m2);
  EXPECT_GT(s.swept_reachable_ratio, 0.8);
  EXPECT_LE(s.swept_reachable_ratio, 1.0);
  EXPECT_NEAR(s.missed_reachable_m2, s.reachable_area_m2 * (1.0 - s.swept_reachable_ratio), 1e-6);
  // The SVG draws the missed floor, measured from the map again: the same
  // area, as rectangles of pixels.
  const std::string svg = RenderPlanSvg(*plan, &map);
  EXPECT_NE(svg.find(absl::StrFormat("missed floor %.1f m", s.missed_reachable_m2)),
            std::string::npos);
  const size_t group = svg.find("<g fill=\"#ff2d95\"");
  ASSERT_NE(group, std::string::npos);
  double drawn = 0.0;
  for (size_t at = svg.find("<rect", group); at < svg.find("</g>", group);
       at = svg.find("<rect", at + 1)) {
    double x, y, w, h;
    ASSERT_EQ(std::sscanf(svg.c_str() + at,
                          "<rect x=\"%lf\" y=\"%lf\" width=\"%lf\" height=\"%lf\"", &x, &y, &w, &h),
              4);
    drawn += w * h;
  }
  EXPECT_NEAR(drawn, s.missed_reachable_m2, 0.01 * s.missed_reachable_m2);
  // The grid's own measure trusts the cells and is not the same figure.
  std::printf("office: reachable %.1f m2, swept %.2f %%, missed %.1f m2, grid coverage %.2f %%\n",
              s.reachable_area_m2, 100.0 * s.swept_reachable_ratio, s.missed_reachable_m2,
              100.0 * s.covered_free_area_ratio);
}

}  // namespace
}  // namespace covplan
