// UnitCosts: each robot's trip to and from every unit of one tour, computed
// with one search per distinct pose on several threads.
#include <cmath>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "planner/fleet/units.h"
#include "tests/fleet/fleet_fixtures.h"

namespace covplan {
namespace {

// Two rooms joined by a door in the middle of the wall between them.
OccupancyMap Rooms() {
  return testing::AsciiMap({"##################",  //
                            "#.......#........#",  //
                            "#.......#........#",  //
                            "#.......#........#",  //
                            "#................#",  //
                            "#................#",  //
                            "#................#",  //
                            "#.......#........#",  //
                            "##################"},
                           8, 0.1);
}

// One tour of Rooms() (robots[0]'s model) and its units.
struct Site {
  Site() : engine(&registry, &cache, EngineLimits{}) {}
  void Plan(const FleetRobot& robot) {
    FleetRequest f;
    f.base.common.time_limit_s = 0.5;
    f.robots.push_back(robot);
    absl::StatusOr<EngineResult> one =
        engine.Plan(testing::SourceOfMap(map, "rooms"), f.RobotRequest(0));
    ASSERT_TRUE(one.ok()) << one.status();
    tour = *std::move(one);
    units = UnitsOfPlan(tour.plan, *tour.area->cover);
  }
  const Grid& drive() const { return *tour.area->drive; }

  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine;
  const OccupancyMap map = Rooms();
  EngineResult tour;
  TourUnits units;
};

// a and c share their start and end; d ends elsewhere.
std::vector<FleetRobot> Robots() {
  std::vector<FleetRobot> robots = {
      testing::Robot("a", 0.8, 1.2, 1.2), testing::Robot("b", 0.8, 13.2, 5.6),
      testing::Robot("c", 0.8, 1.2, 1.2), testing::Robot("d", 0.8, 7.6, 2.8)};
  robots[3].robot.end = Pose2{13.2, 1.2, 0.0};
  return robots;
}

TEST(UnitCosts, ThreadsGiveTheCostsOfOneAndSharedPosesAgree) {
  const std::vector<FleetRobot> robots = Robots();
  Site site;
  site.Plan(robots[0]);
  ASSERT_GT(site.units.units.size(), 4u);
  const Grid& drive = site.drive();
  absl::StatusOr<UnitCosts> one = UnitCosts::Build(site.units, drive, robots, {}, 1);
  ASSERT_TRUE(one.ok()) << one.status();
  for (const int threads : {2, 3, 8}) {
    SCOPED_TRACE(threads);
    absl::StatusOr<UnitCosts> many = UnitCosts::Build(site.units, drive, robots, {}, threads);
    ASSERT_TRUE(many.ok()) << many.status();
    for (int r = 0; r < 4; ++r) {
      for (int u = 0; u < one->num_units(); ++u) {
        EXPECT_EQ(many->Reach(r, u), one->Reach(r, u));
        EXPECT_EQ(many->Return(r, u), one->Return(r, u));
      }
    }
  }
  for (int u = 0; u < one->num_units(); ++u) {
    const TourUnit& t = site.units.units[u];
    // Robots with the same start and end pay the same trips.
    EXPECT_EQ(one->Reach(0, u), one->Reach(2, u));
    EXPECT_EQ(one->Return(0, u), one->Return(2, u));
    // No trip is quicker than the straight line at top speed.
    for (int r = 0; r < 4; ++r) {
      const Pose2& s = *robots[r].robot.start;
      const Pose2& e = *robots[r].robot.end;
      const double speed = robots[r].robot.max_speed_mps;
      EXPECT_TRUE(std::isfinite(one->Reach(r, u)));
      EXPECT_GE(one->Reach(r, u), std::hypot(t.entry.x - s.x, t.entry.y - s.y) / speed - 1e-9);
      EXPECT_GE(one->Return(r, u), std::hypot(t.exit.x - e.x, t.exit.y - e.y) / speed - 1e-9);
    }
  }
}

TEST(UnitCosts, APoseOffTheMapIsRefusedNamingTheRobotWhateverTheThreads) {
  std::vector<FleetRobot> robots = Robots();
  Site site;
  site.Plan(robots[0]);
  robots[2].robot.end = Pose2{40.0, 2.0, 0.0};  // far outside the map
  for (const int threads : {1, 4}) {
    absl::StatusOr<UnitCosts> c = UnitCosts::Build(site.units, site.drive(), robots, {}, threads);
    ASSERT_FALSE(c.ok());
    EXPECT_EQ(c.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(c.status().message().find("robots[2].robot.end"), std::string::npos) << c.status();
  }
}

}  // namespace
}  // namespace covplan
