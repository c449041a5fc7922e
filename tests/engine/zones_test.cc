// Coverage regions and no-go zones on the shipped office map: conformance
// through the path (every reachable cell of the region swept, nothing swept
// or crossed in a zone), zones across a doorway, the corridor and an open
// room, a zone that cuts the building in two, cache sharing, bad areas.
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/geometry/area.h"
#include "planner/grid/map_io.h"
#include "tests/testing/oarp_options.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

// The office of scripts/maps/gen_sample_maps.py in map coordinates (origin
// (-1, -0.5), image y flipped): corridor y 8.5..10.5 m across the building;
// office 2 north of it spans x 5.5..10, y 10.5..18.5 with one 0.9 m door at
// x 7.0..7.9.
OccupancyMap Office() {
  absl::StatusOr<OccupancyMap> map =
      LoadMapFile(std::string(COVPLAN_SOURCE_DIR) + "/maps/sample_office.yaml", MapLoadOptions());
  EXPECT_TRUE(map.ok()) << map.status();
  return *map;
}

PolygonInput Box(double x0, double y0, double x1, double y1) {
  return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}}, {}};
}

PlanOptions Options() {
  PlanOptions o;
  o.robot.tool_width_m = 0.8;
  o.options =
      testing::OarpOptionsWith(TourSolver::kGreedy);  // fast; the tour is not what is tested here
  return o;
}

bool AnySweepInside(const EngineResult& r, double x0, double y0, double x1, double y1) {
  for (const CoverageSweep& s : r.plan.sweeps) {
    for (const CellIndex& c : s.cells) {
      const Point2 p = r.plan.grid->CellCenter(c);
      if (p.x > x0 && p.x < x1 && p.y > y0 && p.y < y1) return true;
    }
  }
  return false;
}

TEST(NoGoZones, DoorwayCorridorAndOpenRoomZonesAreNeverEntered) {
  const OccupancyMap map = Office();
  const std::vector<std::vector<PolygonInput>> cases = {
      {Box(6.8, 10.2, 8.1, 11.0)},                                   // across office 2's door
      {Box(14.13, 8.31, 15.27, 10.77)},                              // across the corridor
      {Box(3.3, 3.3, 5.1, 5.05)},                                    // in the open-plan room
      {{{{16.2, 2.1}, {19.1, 2.6}, {17.3, 5.2}, {16.2, 2.1}}, {}}},  // a triangle, slanted edges
      {Box(1.93, 8.7, 2.61, 9.9), Box(20.07, 8.9, 21.0, 10.3)},      // two zones in the corridor
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(i);
    PlanOptions o = Options();
    o.no_go = cases[i];
    absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_EQ(testing::CheckOarpConformance(*r, o.robot, o.no_go), "");
    EXPECT_GT(r->plan.stats.no_go_cells, 0);
    // Exactly, with the geometry library: no segment has length inside a zone.
    absl::StatusOr<Area> zone = Area::Create(o.no_go, "no_go");
    ASSERT_TRUE(zone.ok());
    for (size_t k = 1; k < r->plan.path.size(); ++k) {
      const Waypoint& a = r->plan.path[k - 1];
      const Waypoint& b = r->plan.path[k];
      ASSERT_LE(zone->SegmentLengthInInterior({a.x, a.y}, {b.x, b.y}), 1e-9) << "segment " << k;
    }
    // No swept cell overlaps a zone.
    for (const CoverageSweep& s : r->plan.sweeps) {
      for (const CellIndex& c : s.cells) {
        const Point2 p = r->plan.grid->CellCenter(c);
        const double h = 0.4;
        ASSERT_LE(zone->BoxOverlapM2(p.x - h, p.y - h, p.x + h, p.y + h), 0.0)
            << c.row << "," << c.col;
      }
    }
  }
}

TEST(NoGoZones, AZoneAcrossTheOnlyDoorLeavesTheRoomUnreachableNotCrossed) {
  const OccupancyMap map = Office();
  PlanOptions o = Options();
  absl::StatusOr<EngineResult> open = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(open.ok()) << open.status();
  ASSERT_TRUE(AnySweepInside(*open, 5.6, 10.6, 9.9, 18.4));  // office 2 is covered without zones
  o.no_go = {Box(6.8, 10.2, 8.1, 11.0)};
  absl::StatusOr<EngineResult> closed = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(closed.ok()) << closed.status();
  EXPECT_EQ(testing::CheckOarpConformance(*closed, o.robot, o.no_go), "");
  EXPECT_FALSE(AnySweepInside(*closed, 5.6, 10.6, 9.9, 18.4));
  // Office 2 (~4.5 m x 8 m) is reported: tens of cells more than without the zone.
  EXPECT_GT(closed->plan.stats.unreachable_free_cells,
            open->plan.stats.unreachable_free_cells + 30);
  EXPECT_LT(closed->plan.stats.free_cells, open->plan.stats.free_cells);
}

TEST(NoGoZones, AZoneAcrossTheCorridorSplitsTheBuildingAndTheSmallerSideIsReported) {
  const OccupancyMap map = Office();
  PlanOptions o = Options();
  o.no_go = {Box(14.13, 8.31, 15.27, 10.77)};
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(testing::CheckOarpConformance(*r, o.robot, o.no_go), "");
  // Both halves hold hundreds of cells; the plan covers one, reports the other.
  EXPECT_GT(r->plan.stats.unreachable_free_cells, 150);
  const bool west = AnySweepInside(*r, -1, -1, 13.5, 20), east = AnySweepInside(*r, 16, -1, 30, 20);
  EXPECT_NE(west, east);
}

TEST(Regions, OnlyCellsInTheRegionAreCoveredAndTheRestMayBeDrivenThrough) {
  const OccupancyMap map = Office();
  PlanOptions o = Options();
  // Two rooms on opposite ends of the corridor: the robot must drive along
  // the corridor between them without covering it.
  o.regions = {Box(-0.2, 10.6, 5.4, 18.4), Box(23.1, 0.6, 28.3, 5.4)};
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(testing::CheckOarpConformance(*r, o.robot), "");
  absl::StatusOr<Area> region = Area::Create(o.regions, "regions");
  ASSERT_TRUE(region.ok());
  const double cell = 0.8, h = cell / 2;
  int64_t in_region = 0;
  for (const CoverageSweep& s : r->plan.sweeps) {
    for (const CellIndex& c : s.cells) {
      const Point2 p = r->plan.grid->CellCenter(c);
      // Every swept cell lies mostly inside a region.
      ASSERT_GT(region->BoxOverlapM2(p.x - h, p.y - h, p.x + h, p.y + h), 0.5 * cell * cell);
      ++in_region;
    }
  }
  EXPECT_EQ(in_region, r->plan.stats.covered_cells);
  EXPECT_TRUE(AnySweepInside(*r, -0.2, 10.6, 5.4, 18.4));
  EXPECT_TRUE(AnySweepInside(*r, 23.1, 0.6, 28.3, 5.4));
  EXPECT_GT(r->plan.stats.transition_length_m, 15.0);  // crosses the building
  // Cells cut by the region edges are not swept: the share is below the
  // whole map's (0.89) but most of the regions' free area.
  EXPECT_GT(r->plan.stats.covered_free_area_ratio, 0.6);
  EXPECT_LE(r->plan.stats.covered_free_area_ratio, 1.0);
}

TEST(Regions, RegionsAndNoGoTogether) {
  const OccupancyMap map = Office();
  PlanOptions o = Options();
  o.regions = {Box(-0.2, 0.6, 11.0, 8.4)};
  o.no_go = {Box(3.3, 3.3, 5.1, 5.05),
             Box(9.03, 8.0, 10.3, 8.9)};  // the second blocks the double door
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(testing::CheckOarpConformance(*r, o.robot, o.no_go), "");
}

TEST(Zones, ShareTheMapsGridAndAZonelessRequestStillHitsTheCache) {
  const OccupancyMap map = Office();
  LocalArtifactCache cache;
  PlanOptions plain = Options();
  ASSERT_TRUE(PlanCoverage(map, plain, &cache, "office").ok());
  // grid, area, floor, partition, transitions, and the remembered plan (a
  // greedy tour: no remembered tour to warm-start from).
  const size_t after_plain = cache.size();
  EXPECT_EQ(after_plain, 6u);
  PlanOptions zoned = Options();
  zoned.no_go = {Box(3.3, 3.3, 5.1, 5.05)};
  absl::StatusOr<CoveragePlan> z = PlanCoverage(map, zoned, &cache, "office");
  ASSERT_TRUE(z.ok()) << z.status();
  EXPECT_FALSE(z->stats.decomposition_cached);
  // The grid is shared; area, floor, partition, transitions, plan are new.
  EXPECT_EQ(cache.size(), after_plain + 5);
  absl::StatusOr<CoveragePlan> again = PlanCoverage(map, plain, &cache, "office");
  ASSERT_TRUE(again.ok());
  EXPECT_TRUE(again->stats.decomposition_cached);
  absl::StatusOr<CoveragePlan> zoned_again = PlanCoverage(map, zoned, &cache, "office");
  ASSERT_TRUE(zoned_again.ok());
  EXPECT_TRUE(zoned_again->stats.decomposition_cached);
  // The same zones in another vertex order and orientation share the key.
  PlanOptions reordered = Options();
  reordered.no_go = {{{{5.1, 5.05}, {5.1, 3.3}, {3.3, 3.3}, {3.3, 5.05}, {5.1, 5.05}}, {}}};
  absl::StatusOr<CoveragePlan> r = PlanCoverage(map, reordered, &cache, "office");
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->stats.decomposition_cached);
  EXPECT_EQ(r->stats.plan_source, PlanOrigin::kCacheHit);  // the zones' plan, too
  EXPECT_EQ(cache.size(), after_plain + 5);
}

TEST(Zones, BadAreasAreInvalidArgumentNamingTheRingOrVertex) {
  const OccupancyMap map = Office();
  struct Case {
    std::vector<PolygonInput> regions, no_go;
    const char* message;
  };
  const double nan = std::nan("");
  const std::vector<Case> cases = {
      {{}, {{{{1, 1}, {3, 1}, {1, 3}, {3, 3}, {1, 1}}, {}}}, "no_go[0].outer"},  // bow tie
      {{}, {{{{1, 1}, {3, 1}, {3, 3}, {1, 3}}, {}}}, "not closed"},              // open ring
      {{}, {{{{1, 1}, {3, 1}, {1, 1}}, {}}}, "at least 3"},                      // 2 points
      {{Box(1, 1, 3, 3), {{{1, 1}, {nan, 1}, {3, 3}, {1, 1}}, {}}},
       {},
       "regions[1].outer vertex 1"},
      {{}, {{{{1, 1}, {INFINITY, 1}, {3, 3}, {1, 1}}, {}}}, "no_go[0].outer vertex 1"},
      {{}, {Box(100, 100, 101, 101)}, "no_go[0] lies outside the map"},
      {{Box(-30, -30, -20, -20)}, {}, "regions[0] lies outside the map"},
      {{Box(23.5, 1.5, 28.5, 5.5)}, {Box(23, 1, 29, 6)}, "regions: no free"},  // region all no-go
      {{Box(25.0, 12.0, 25.3, 12.3)}, {}, "regions: no free"},  // smaller than a cell
      {{},
       {{Box(1, 1, 5, 5).outer, {{{2, 2}, {6, 2}, {6, 3}, {2, 3}, {2, 2}}}}},
       "no_go[0].holes[0]"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    PlanOptions o = Options();
    o.regions = cases[i].regions;
    o.no_go = cases[i].no_go;
    absl::StatusOr<CoveragePlan> r = PlanCoverage(map, o);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << i << ": " << r.status();
    EXPECT_THAT(std::string(r.status().message()), HasSubstr(cases[i].message)) << i;
  }
  // Too many vertices for the configured limit.
  PlanOptions o = Options();
  PolygonInput circle;
  for (int k = 0; k < 200; ++k) {
    circle.outer.push_back(
        {12 + 2 * std::cos(k * 2 * M_PI / 200), 4 + 2 * std::sin(k * 2 * M_PI / 200)});
  }
  circle.outer.push_back(circle.outer.front());
  o.no_go = {circle};
  EngineLimits limits;
  limits.max_area_vertices = 100;
  absl::StatusOr<CoveragePlan> r = PlanCoverage(map, o, nullptr, "local", limits);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("limit of 100"));
  limits.max_area_vertices = 1000;
  EXPECT_TRUE(PlanCoverage(map, o, nullptr, "local", limits).ok());
}

TEST(Zones, StartPoseInsideANoGoZoneIsRefused) {
  const OccupancyMap map = Office();
  PlanOptions o = Options();
  o.no_go = {Box(3.3, 3.3, 5.1, 5.05)};
  o.robot.start = Pose2{4.0, 4.0, 0.0};
  absl::StatusOr<CoveragePlan> r = PlanCoverage(map, o);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("robot.start"));
  o.robot.start.reset();
  o.robot.end = Pose2{4.0, 4.0, 0.0};
  r = PlanCoverage(map, o);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("robot.end"));
}

}  // namespace
}  // namespace covplan
