// Polygon maps: cells are free by their exact area inside the polygons. A
// polygon map and its rasterised twin (the same geometry drawn at 0.05 m)
// give the same free cells up to the cells the rasterisation itself can
// change; rank counts stay optimal; drive lines stay in the free space.
#include <cmath>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"
#include "planner/engine/site.h"
#include "planner/geometry/area.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

constexpr double kRes = 0.05;

// An L-shaped building with a pillar, a slanted planter and a thick wall
// stub as holes, plus a detached shed (its own polygon).
std::vector<PolygonInput> Site() {
  PolygonInput main;
  main.outer = {{0.13, 0.07},   {20.02, 0.07}, {20.02, 8.11}, {12.04, 8.11},
                {12.04, 14.03}, {0.13, 14.03}, {0.13, 0.07}};
  main.holes = {
      {{4.0, 4.0}, {5.0, 4.0}, {5.0, 5.0}, {4.0, 5.0}, {4.0, 4.0}},
      {{14.0, 2.0}, {17.0, 2.5}, {15.0, 5.5}, {14.0, 2.0}},
      {{5.85, 9.0}, {6.25, 9.0}, {6.25, 13.5}, {5.85, 13.5}, {5.85, 9.0}},
  };
  PolygonInput shed;
  shed.outer = {{22.0, 0.5}, {26.3, 0.5}, {26.3, 4.4}, {22.0, 4.4}, {22.0, 0.5}};
  return {main, shed};
}

Area SiteArea() {
  absl::StatusOr<Area> a = Area::Create(Site(), "map.polygons");
  EXPECT_TRUE(a.ok()) << a.status();
  return *a;
}

TEST(PolygonMap, MatchesItsRasterisedTwinUpToRasterisationCells) {
  const Area area = SiteArea();
  absl::StatusOr<SiteMap> site =
      SiteFromPolygons(std::make_shared<const Area>(area), kRes, 64'000'000);
  ASSERT_TRUE(site.ok()) << site.status();
  absl::StatusOr<OccupancyMap> twin = RasterizeArea(area, kRes, RasterRule::kCentre);
  ASSERT_TRUE(twin.ok()) << twin.status();
  for (double tool : {0.5, 0.8, 1.1}) {
    SCOPED_TRACE(tool);
    GridOptions go;
    go.cell_size = tool;
    absl::StatusOr<std::shared_ptr<const GridArtifact>> poly = BuildGridArtifact(*site, go);
    ASSERT_TRUE(poly.ok()) << poly.status();
    absl::StatusOr<Grid> raster = BuildGrid(*twin, go);
    ASSERT_TRUE(raster.ok()) << raster.status();
    const Grid& g = *(*poly)->grid;
    ASSERT_EQ(g.rows(), raster->rows());
    ASSERT_EQ(g.cols(), raster->cols());
    int differing = 0;
    for (int r = 0; r < g.rows(); ++r) {
      for (int c = 0; c < g.cols(); ++c) {
        if (g.IsFree(r, c) == raster->IsFree(r, c)) continue;
        ++differing;
        // The twin can only differ where boundary pixels decide: the exact
        // fraction lies within their total area of one half.
        const double x0 = g.origin().x + c * tool, y0 = g.origin().y + r * tool;
        double boundary = 0.0;
        for (double y = y0; y < y0 + tool - 1e-9; y += kRes) {
          for (double x = x0; x < x0 + tool - 1e-9; x += kRes) {
            const double o = area.BoxOverlapM2(x, y, x + kRes, y + kRes);
            if (o > 0.0 && o < kRes * kRes) boundary += kRes * kRes;
          }
        }
        const double exact = area.BoxOverlapM2(x0, y0, x0 + tool, y0 + tool) / (tool * tool);
        EXPECT_LE(std::abs(exact - 0.5), boundary / (tool * tool) + 1e-6)  // 1e-6: float fractions
            << "cell " << r << "," << c << " exact " << exact;
      }
    }
    EXPECT_LT(differing, g.CountFree() / 50 + 2);
    // Exact fractions: a cell is free iff more than half of it is inside.
    for (int r = 0; r < g.rows(); ++r) {
      for (int c = 0; c < g.cols(); ++c) {
        const double x0 = g.origin().x + c * tool, y0 = g.origin().y + r * tool;
        const double exact = area.BoxOverlapM2(x0, y0, x0 + tool, y0 + tool) / (tool * tool);
        if (std::abs(exact - 0.5) > 1e-6) {
          ASSERT_EQ(g.IsFree(r, c), exact > 0.5) << r << "," << c;
        }
      }
    }
    // The rank count on the polygon grid is the optimum (LP = min-cut).
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    auto lp = LpPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok() && lp.ok());
    EXPECT_EQ(cut->ranks.size(), lp->ranks.size());
    EXPECT_EQ(testing::CheckExactCover(g, cut->ranks), "");
  }
}

TEST(PolygonMap, PlansConformAndDriveLinesStayInTheFreeSpace) {
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  MapSource source;
  source.map_id = "site";
  source.load = []() {
    return SiteFromPolygons(std::make_shared<const Area>(SiteArea()), kRes, 64'000'000);
  };
  PlanRequest r;
  r.common.robot.tool_width_m = 0.6;
  r.common.time_limit_s = 0.3;
  r.no_go = {{{{8.1, 2.2}, {9.9, 2.2}, {9.9, 3.9}, {8.1, 3.9}, {8.1, 2.2}}, {}}};
  absl::StatusOr<EngineResult> result = engine.Plan(source, r);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(testing::CheckOarpConformance(*result, r.common.robot, r.no_go), "");
  // The shed is a separate polygon: reported unreachable, not planned.
  EXPECT_GT(result->plan.stats.unreachable_free_cells, 20);
  EXPECT_NEAR(result->plan.stats.map_free_area_m2, SiteArea().AreaM2(), 1e-6);
  // Obstacles are the holes and everything outside the outer ring.
  const std::vector<PolygonInput> site = Site();
  std::vector<PolygonInput> obstacles;
  for (const auto& hole : site[0].holes) obstacles.push_back({hole, {}});
  EXPECT_EQ(testing::CheckPathAvoidsZones(result->plan.path, obstacles), "");
  for (size_t i = 1; i < result->plan.path.size(); ++i) {
    const Waypoint& a = result->plan.path[i - 1];
    const Waypoint& b = result->plan.path[i];
    for (int k = 0; k <= 100; ++k) {
      const double x = a.x + k / 100.0 * (b.x - a.x), y = a.y + k / 100.0 * (b.y - a.y);
      ASSERT_TRUE(testing::InsideRing(site[0].outer, x, y) ||
                  testing::BoundaryDistance(site[0], x, y) < 1e-6)
          << "segment " << i << " leaves the site at (" << x << ", " << y << ")";
    }
  }
}

}  // namespace
}  // namespace covplan
