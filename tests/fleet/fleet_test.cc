// Fleet plans through the engine: a fleet of one is the single plan; every
// planner's fleet sweeps every cell once per robot share and conforms per
// robot; robots in separate rooms keep to their own; the equal-area
// baseline gives equal shares; a failed robot's cells reappear in the
// others' plans; bad fleets are refused naming the field.
#include <algorithm>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fleet/fleet_fixtures.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;
using testing::Robot;

FleetRequest Fleet(const std::string& planner, double budget) {
  FleetRequest f;
  f.base.planner = planner;
  f.base.common.time_limit_s = budget;
  f.base.common.robot.tool_width_m = 0.8;
  return f;
}

TEST(Fleet, OfOneIsTheSingleRobotPlan) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache_a, cache_b;
  EngineLimits limits;
  limits.plan_memory = false;
  PlanningEngine fleet_engine(&registry, &cache_a, limits), single(&registry, &cache_b, limits);
  // A budget the search converges within (its plan is then the seed's alone,
  // however loaded the machine is).
  FleetRequest f = Fleet("oarp", 20.0);
  f.robots = {Robot("only", 0.8, 1.5, 1.5)};
  absl::StatusOr<FleetPlan> fleet = PlanFleet(fleet_engine, testing::SourceOfMap(map, "office"), f);
  ASSERT_TRUE(fleet.ok()) << fleet.status();
  absl::StatusOr<EngineResult> one =
      single.Plan(testing::SourceOfMap(map, "office"), f.RobotRequest(0));
  ASSERT_TRUE(one.ok()) << one.status();
  const CoveragePlan& a = fleet->robots[0].result.plan;
  ASSERT_EQ(a.path.size(), one->plan.path.size());
  for (size_t i = 0; i < a.path.size(); ++i) {
    EXPECT_EQ(a.path[i].x, one->plan.path[i].x);
    EXPECT_EQ(a.path[i].y, one->plan.path[i].y);
    EXPECT_EQ(a.path[i].kind, one->plan.path[i].kind);
  }
  EXPECT_EQ(fleet->makespan_s, one->plan.stats.estimated_duration_s);
  EXPECT_EQ(testing::CheckFleetPlan(*fleet, f, *one->area), "");
  // The fleet's floor is the plan's own.
  EXPECT_GT(fleet->floor.reachable_area_m2, 0.0);
  EXPECT_DOUBLE_EQ(fleet->floor.reachable_area_m2, one->plan.stats.reachable_area_m2);
  EXPECT_DOUBLE_EQ(fleet->floor.swept_reachable_ratio, one->plan.stats.swept_reachable_ratio);
  EXPECT_DOUBLE_EQ(fleet->floor.missed_reachable_m2, one->plan.stats.missed_reachable_m2);
}

class EveryPlanner : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryPlanner, EveryRobotConformsAndTogetherTheySweepEveryCell) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  for (FleetDivision division : {FleetDivision::kMakespan, FleetDivision::kEqualArea}) {
    for (int k : {2, 3}) {
      SCOPED_TRACE(absl::StrFormat("%s k=%d", FleetDivisionName(division), k));
      LocalArtifactCache cache;
      PlanningEngine engine(&registry, &cache, EngineLimits{});
      FleetRequest f = Fleet(GetParam(), 1.0);
      f.division = division;
      f.base.no_go = {{{{6.1, 3.3}, {7.7, 3.6}, {7.2, 5.1}, {6.1, 3.3}}, {}}};
      const std::vector<Point2> starts = {{1.5, 1.5}, {20.0, 1.5}, {10.0, 10.0}};
      for (int r = 0; r < k; ++r)
        f.robots.push_back(Robot("r" + std::to_string(r), 0.8, starts[r].x, starts[r].y));
      const MapSource source = testing::SourceOfMap(map, "office");
      absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, source, f);
      ASSERT_TRUE(fleet.ok()) << fleet.status();
      absl::StatusOr<std::shared_ptr<const CoverageArea>> whole =
          engine.AreaFor(source, f.RobotRequest(0));
      ASSERT_TRUE(whole.ok());
      EXPECT_EQ(testing::CheckFleetPlan(*fleet, f, **whole), "");
      EXPECT_EQ(fleet->covered_cells, (*whole)->cover_cells);
      int64_t assigned = 0;
      for (const FleetRobotPlan& rp : fleet->robots) assigned += rp.assigned_cells;
      EXPECT_EQ(assigned, (*whole)->cover_cells) << "every cell belongs to exactly one robot";
      // The floor the robots sweep together: at least what any one of them
      // sweeps, at most what they sweep added up, and most of what the tool
      // can reach (they sweep every cell).
      absl::StatusOr<std::shared_ptr<const FloorArtifact>> floor =
          engine.FloorFor(source, f.RobotRequest(0));
      ASSERT_TRUE(floor.ok()) << floor.status();
      const FloorMeasure& all = fleet->floor;
      EXPECT_DOUBLE_EQ(
          all.reachable_area_m2,
          MeasureFloor((*floor)->reach, std::vector<Waypoint>{}, false).reachable_area_m2);
      double most = 0.0, sum = 0.0;
      for (const FleetRobotPlan& rp : fleet->robots) {
        const double m =
            MeasureFloor((*floor)->reach, rp.result.plan.path, false).swept_reachable_m2;
        most = std::max(most, m);
        sum += m;
      }
      EXPECT_GE(all.swept_reachable_m2, most);
      EXPECT_LE(all.swept_reachable_m2, sum + 1e-9);
      EXPECT_GT(all.swept_reachable_ratio, 0.85);
      EXPECT_NEAR(all.missed_reachable_m2, all.reachable_area_m2 - all.swept_reachable_m2, 1e-9);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryPlanner, ::testing::ValuesIn(BuiltinPlanners().Names()));

// Two rooms joined by a long corridor below them; a robot in each room
// sweeps its own room (the corridor may go to either).
TEST(Fleet, RobotsInSeparateRoomsEachGetTheirOwnRoom) {
  const OccupancyMap map = testing::AsciiMap(
      {
          "#########################",
          "#.......#########.......#",
          "#.......#########.......#",
          "#.......#########.......#",
          "#.......#########.......#",
          "#.......#########.......#",
          "###.###############.#####",
          "###.###############.#####",
          "###.................#####",
          "#########################",
      },
      8, 0.1);  // 0.8 m cells: 7 x 5 cells a room
  const PlannerRegistry registry = BuiltinPlanners();
  for (const std::string planner : {"oarp", "boustrophedon", "stc"}) {
    SCOPED_TRACE(planner);
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, EngineLimits{});
    FleetRequest f = Fleet(planner, 1.0);
    f.robots = {Robot("west", 0.8, 2.0, 5.2), Robot("east", 0.8, 16.4, 5.2)};
    absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, testing::SourceOfMap(map, "rooms"), f);
    ASSERT_TRUE(fleet.ok()) << fleet.status();
    for (const FleetRobotPlan& rp : fleet->robots) {
      const bool west = rp.id == "west";
      int64_t own = 0, other = 0;
      for (const CoverageSweep& s : rp.result.plan.sweeps) {
        for (const CellIndex& c : s.cells) {
          const Point2 p = rp.result.plan.grid->CellCenter(c);
          if (p.y < 3.2) continue;  // the corridor
          ((p.x < 9.6) == west ? own : other) += 1;
        }
      }
      EXPECT_EQ(other, 0) << rp.id << " sweeps cells of the other room";
      EXPECT_EQ(own, 35) << rp.id << " leaves cells of its own room to the other robot";
    }
  }
}

TEST(Fleet, EqualAreaSharesAreEqual) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  FleetRequest f = Fleet("oarp", 1.0);
  f.division = FleetDivision::kEqualArea;
  f.robots = {Robot("a", 0.8, 1.5, 1.5), Robot("b", 0.8, 20.0, 1.5), Robot("c", 0.8, 10.0, 10.0)};
  absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, testing::SourceOfMap(map, "office"), f);
  ASSERT_TRUE(fleet.ok()) << fleet.status();
  int64_t lo = INT64_MAX, hi = 0;
  for (const FleetRobotPlan& rp : fleet->robots) {
    lo = std::min(lo, rp.assigned_cells);
    hi = std::max(hi, rp.assigned_cells);
  }
  EXPECT_LE(hi - lo, fleet->cover_cells / 20) << lo << " .. " << hi;
}

TEST(Fleet, AFailedRobotsCellsReappearInTheOthersPlans) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const MapSource source = testing::SourceOfMap(map, "office");
  FleetRequest f = Fleet("oarp", 1.0);
  f.robots = {Robot("a", 0.8, 1.5, 1.5), Robot("b", 0.8, 20.0, 1.5), Robot("c", 0.8, 10.0, 10.0)};
  absl::StatusOr<FleetPlan> three = PlanFleet(engine, source, f);
  ASSERT_TRUE(three.ok()) << three.status();
  // Robot b fails before it sweeps anything: its cells go to a and c.
  const CoveragePlan& failed = three->robots[1].result.plan;
  std::vector<uint8_t> mask(static_cast<size_t>(failed.grid->size()), 0);
  int64_t left = 0;
  for (const CoverageSweep& s : failed.sweeps) {
    for (const CellIndex& c : s.cells) left += !mask[failed.grid->Index(c.row, c.col)]++;
  }
  ASSERT_GT(left, 0);
  FleetRequest rest = f;
  rest.robots = {f.robots[0], f.robots[2]};
  rest.cover_mask = mask;
  absl::StatusOr<FleetPlan> two = PlanFleet(engine, source, rest);
  ASSERT_TRUE(two.ok()) << two.status();
  std::vector<uint8_t> swept(mask.size(), 0);
  for (const FleetRobotPlan& rp : two->robots) {
    for (const CoverageSweep& s : rp.result.plan.sweeps) {
      for (const CellIndex& c : s.cells) swept[rp.result.plan.grid->Index(c.row, c.col)] = 1;
    }
  }
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) {
      ASSERT_TRUE(swept[i]) << "cell " << i << " of the failed robot is lost";
    }
  }
  EXPECT_EQ(two->cover_cells, left);
}

TEST(Fleet, MasksOfTheWrongShapeAreRefused) {
  const OccupancyMap map = testing::LoadShippedMap("small_rooms.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const MapSource source = testing::SourceOfMap(map, "rooms");
  FleetRequest f = Fleet("oarp", 0.2);
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("b", 0.8, 4.0, 1.2)};
  f.drive_mask = {1, 1, 1};
  absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, source, f);
  EXPECT_EQ(fleet.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(fleet.status().message()), HasSubstr("drive_mask: given without"));
  absl::StatusOr<std::shared_ptr<const CoverageArea>> area =
      engine.AreaFor(source, f.RobotRequest(0));
  ASSERT_TRUE(area.ok()) << area.status();
  f.cover_mask.assign(static_cast<size_t>((*area)->cover->size()), 1);
  fleet = PlanFleet(engine, source, f);
  EXPECT_EQ(fleet.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(fleet.status().message()), HasSubstr("drive mask has 3 entries"));
}

TEST(Fleet, SafetyReportFindsRobotsThatStartTogether) {
  const OccupancyMap map = testing::LoadShippedMap("small_rooms.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  FleetRequest f = Fleet("oarp", 0.5);
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("b", 0.8, 1.2, 1.2)};
  absl::StatusOr<FleetPlan> fleet = PlanFleet(engine, testing::SourceOfMap(map, "rooms"), f);
  ASSERT_TRUE(fleet.ok()) << fleet.status();
  EXPECT_EQ(fleet->safety.closest_approach_m, 0.0);
  EXPECT_EQ(fleet->safety.closest_at_s, 0.0);
  ASSERT_FALSE(fleet->safety.conflicts.empty());
  EXPECT_EQ(fleet->safety.conflicts[0].start_s, 0.0);
  EXPECT_EQ(fleet->safety.clearance_m, 0.8);
}

TEST(Fleet, BadFleetsAreRefusedNamingTheField) {
  const OccupancyMap map = testing::LoadShippedMap("small_rooms.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const MapSource source = testing::SourceOfMap(map, "rooms");
  auto refused = [&](const FleetRequest& f) {
    absl::StatusOr<FleetPlan> p = PlanFleet(engine, source, f);
    EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument) << p.status();
    return std::string(p.status().message());
  };
  FleetRequest f = Fleet("oarp", 0.3);
  EXPECT_THAT(refused(f), HasSubstr("robots: a fleet plan needs at least one robot"));
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("a", 0.8, 2.0, 1.2)};
  EXPECT_THAT(refused(f), HasSubstr("robots[1].id: 'a' is already the id of robots[0]"));
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("", 0.8, 2.0, 1.2)};
  EXPECT_THAT(refused(f), HasSubstr("robots[1].id: must not be empty"));
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("b", 0.5, 2.0, 1.2)};
  EXPECT_THAT(refused(f), HasSubstr("robots[1].robot.tool_width_m: 0.5 differs"));
  f.robots.clear();
  for (int i = 0; i <= FleetRequest::kMaxRobots; ++i)
    f.robots.push_back(Robot("r" + std::to_string(i), 0.8, 1.2, 1.2));
  EXPECT_THAT(refused(f), HasSubstr("robots: at most 64 robots per fleet, got 65"));
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("b", 0.8, -50.0, -50.0)};
  EXPECT_THAT(refused(f), HasSubstr("robots[1]"));
  f.robots = {Robot("a", 0.8, 1.2, 1.2), Robot("b", 0.8, 1.2, 1.2)};
  f.robots[1].robot.max_speed_mps = -1;
  EXPECT_THAT(refused(f), HasSubstr("robots[1].robot.max_speed_mps"));
}

}  // namespace
}  // namespace covplan
