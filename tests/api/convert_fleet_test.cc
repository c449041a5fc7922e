// The fleet half of the proto edge: a FleetRequest survives the trip to a
// PlanFleetRequest and back, each robot's own PlanRequest is the base with
// its model and battery, bad fleets are refused naming the field, and a
// fleet plan survives the trip to a PlanFleetResponse and back.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "api/convert_fleet.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/artifact_cache.h"
#include "planner/fleet/fleet_planner.h"
#include "tests/fleet/fleet_fixtures.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

v1::PlanRequest BaseProto() {
  v1::PlanRequest base;
  base.set_map_id(std::string(64, 'f'));
  base.set_planner("boustrophedon");
  base.mutable_boustrophedon()->set_sweep_axis(v1::SWEEP_AXIS_VERTICAL);
  base.set_time_limit_s(1.5);
  base.set_seed(7);
  base.set_min_free_fraction(0.6);
  v1::Ring* ring = base.add_no_go()->mutable_outer();
  for (auto [x, y] : {std::pair{1.0, 1.0}, {2.0, 1.0}, {2.0, 2.0}, {1.0, 1.0}}) {
    v1::Point2* p = ring->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  // Ignored: each robot brings its own.
  base.mutable_robot()->set_tool_width_m(0.3);
  base.mutable_battery()->set_capacity(1);
  return base;
}

FleetRequest TwoRobots() {
  FleetRequest f;
  FleetRobot a;
  a.id = "a";
  a.robot.tool_width_m = 0.5;
  a.robot.max_speed_mps = 0.7;
  a.robot.acceleration_mps2 = 0.3;
  a.robot.turn_rate_deg_s = 45;
  a.robot.start = Pose2{1.0, 2.0, 0.5};
  a.robot.end = Pose2{3.0, 4.0, -0.5};
  FleetRobot b;
  b.id = "b";
  b.robot.tool_width_m = 0.5;
  b.robot.max_speed_mps = 1.2;
  BatteryOptions battery;
  battery.capacity = 200;
  battery.reserve = 10;
  battery.station = Pose2{5.0, 6.0, 1.0};
  battery.energy.per_metre = 2;
  battery.energy.per_turn = 0.5;
  battery.energy.per_second = 0.1;
  battery.interruptible_units = true;
  battery.atomic_units = {3, 4};
  b.battery = battery;
  b.recharge_s = 600;
  f.robots = {a, b};
  f.division = FleetDivision::kEqualArea;
  f.clearance_m = 1.25;
  return f;
}

void ExpectSameRobot(const FleetRobot& got, const FleetRobot& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.robot.tool_width_m, want.robot.tool_width_m);
  EXPECT_EQ(got.robot.max_speed_mps, want.robot.max_speed_mps);
  EXPECT_EQ(got.robot.acceleration_mps2, want.robot.acceleration_mps2);
  EXPECT_EQ(got.robot.turn_rate_deg_s, want.robot.turn_rate_deg_s);
  ASSERT_EQ(got.robot.start.has_value(), want.robot.start.has_value());
  if (want.robot.start) {
    EXPECT_EQ(got.robot.start->x, want.robot.start->x);
    EXPECT_EQ(got.robot.start->theta, want.robot.start->theta);
  }
  ASSERT_EQ(got.robot.end.has_value(), want.robot.end.has_value());
  if (want.robot.end) {
    EXPECT_EQ(got.robot.end->y, want.robot.end->y);
  }
  ASSERT_EQ(got.battery.has_value(), want.battery.has_value());
  if (want.battery) {
    EXPECT_EQ(got.battery->capacity, want.battery->capacity);
    EXPECT_EQ(got.battery->reserve, want.battery->reserve);
    EXPECT_EQ(got.battery->station.x, want.battery->station.x);
    EXPECT_EQ(got.battery->station.theta, want.battery->station.theta);
    EXPECT_EQ(got.battery->energy.per_metre, want.battery->energy.per_metre);
    EXPECT_EQ(got.battery->energy.per_turn, want.battery->energy.per_turn);
    EXPECT_EQ(got.battery->energy.per_second, want.battery->energy.per_second);
    EXPECT_EQ(got.battery->interruptible_units, want.battery->interruptible_units);
    EXPECT_EQ(got.battery->atomic_units, want.battery->atomic_units);
  }
  EXPECT_EQ(got.recharge_s, want.recharge_s);
}

TEST(ConvertFleet, RequestRoundTrip) {
  const FleetRequest want = TwoRobots();
  v1::PlanFleetRequest proto;
  FleetRequestToProto(want, BaseProto(), &proto);
  EXPECT_FALSE(proto.plan().has_robot());
  EXPECT_FALSE(proto.plan().has_battery());
  EXPECT_EQ(proto.division(), v1::FLEET_DIVISION_EQUAL_AREA);
  absl::StatusOr<FleetRequest> got = FleetRequestFromProto(proto);
  ASSERT_TRUE(got.ok()) << got.status();
  ASSERT_EQ(got->robots.size(), 2u);
  for (size_t i = 0; i < 2; ++i) ExpectSameRobot(got->robots[i], want.robots[i]);
  EXPECT_EQ(got->division, FleetDivision::kEqualArea);
  EXPECT_EQ(got->clearance_m, 1.25);
  // The base: everything but the robot and battery, which come from robot 0.
  EXPECT_EQ(got->base.planner, "boustrophedon");
  EXPECT_NE(got->base.options, nullptr);
  EXPECT_EQ(got->base.common.time_limit_s, 1.5);
  EXPECT_EQ(got->base.common.seed, 7u);
  EXPECT_EQ(got->base.common.min_free_fraction, 0.6);
  EXPECT_EQ(got->base.no_go.size(), 1u);
  EXPECT_EQ(got->base.common.robot.tool_width_m, 0.5);
  EXPECT_EQ(got->base.common.robot.max_speed_mps, 0.7);
  EXPECT_FALSE(got->base.battery.has_value());
  const PlanRequest second = got->RobotRequest(1);
  EXPECT_EQ(second.common.robot.max_speed_mps, 1.2);
  ASSERT_TRUE(second.battery.has_value());
  EXPECT_EQ(second.battery->capacity, 200);

  // And back again: the same proto.
  v1::PlanFleetRequest again;
  FleetRequestToProto(*got, BaseProto(), &again);
  EXPECT_EQ(again.SerializeAsString(), proto.SerializeAsString());
}

TEST(ConvertFleet, RobotPlanRequestIsTheBaseWithTheRobot) {
  v1::PlanFleetRequest proto;
  FleetRequestToProto(TwoRobots(), BaseProto(), &proto);
  const v1::PlanRequest a = FleetRobotPlanRequest(proto, 0);
  const v1::PlanRequest b = FleetRobotPlanRequest(proto, 1);
  EXPECT_EQ(a.map_id(), BaseProto().map_id());
  EXPECT_EQ(a.seed(), 7u);
  EXPECT_EQ(a.no_go_size(), 1);
  EXPECT_EQ(a.robot().max_speed_mps(), 0.7);
  EXPECT_FALSE(a.has_battery());
  EXPECT_EQ(b.robot().max_speed_mps(), 1.2);
  EXPECT_EQ(b.battery().capacity(), 200);
  // Converted, it is the robot's request.
  absl::StatusOr<PlanRequest> converted = PlanRequestFromProto(b);
  ASSERT_TRUE(converted.ok()) << converted.status();
  EXPECT_EQ(converted->common.robot.max_speed_mps, 1.2);
  EXPECT_EQ(converted->battery->station.y, 6.0);
}

TEST(ConvertFleet, BadFleetsNameTheField) {
  struct Case {
    std::string name;
    std::function<void(v1::PlanFleetRequest*)> spoil;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"no robots", [](v1::PlanFleetRequest* r) { r->clear_robots(); },
       "robots: a fleet plan needs at least one robot"},
      {"duplicate ids", [](v1::PlanFleetRequest* r) { r->mutable_robots(1)->set_id("a"); },
       "robots[1].id: 'a' is already the id of robots[0]"},
      {"two tool widths",
       [](v1::PlanFleetRequest* r) { r->mutable_robots(1)->mutable_robot()->set_tool_width_m(1); },
       "robots[1].robot.tool_width_m: 1 differs from robots[0]'s 0.5"},
      {"bad speed",
       [](v1::PlanFleetRequest* r) {
         r->mutable_robots(0)->mutable_robot()->set_max_speed_mps(-1);
       },
       "robots[0].robot.max_speed_mps"},
      {"battery without station",
       [](v1::PlanFleetRequest* r) { r->mutable_robots(1)->mutable_battery()->clear_station(); },
       "robots[1].battery.station is required"},
      {"base time limit", [](v1::PlanFleetRequest* r) { r->mutable_plan()->set_time_limit_s(-3); },
       "plan.time_limit_s"},
      {"base planner options", [](v1::PlanFleetRequest* r) { r->mutable_plan()->mutable_stc(); },
       "plan.planner_options"},
      {"division",
       [](v1::PlanFleetRequest* r) { r->set_division(static_cast<v1::FleetDivision>(9)); },
       "division: unknown value 9"},
      {"clearance", [](v1::PlanFleetRequest* r) { r->set_clearance_m(1e9); }, "clearance_m"},
      {"too many",
       [](v1::PlanFleetRequest* r) {
         for (int i = 0; i < 100; ++i) *r->add_robots() = r->robots(0);
       },
       "robots: at most 64 robots per fleet, got 102"},
  };
  for (const Case& c : cases) {
    v1::PlanFleetRequest proto;
    FleetRequestToProto(TwoRobots(), BaseProto(), &proto);
    c.spoil(&proto);
    absl::StatusOr<FleetRequest> got = FleetRequestFromProto(proto);
    ASSERT_FALSE(got.ok()) << c.name;
    EXPECT_EQ(got.status().code(), absl::StatusCode::kInvalidArgument) << c.name;
    EXPECT_THAT(std::string(got.status().message()), HasSubstr(c.message)) << c.name;
  }
}

TEST(ConvertFleet, PlanRoundTrip) {
  const OccupancyMap map = testing::AsciiMap({"##########",  //
                                              "#........#",  //
                                              "#........#",  //
                                              "#...##...#",  //
                                              "#........#",  //
                                              "##########"},
                                             8, 0.1);
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  const PlanningEngine engine(&registry, &cache, EngineLimits());
  FleetRequest f;
  f.base.common.time_limit_s = 1;
  f.robots = {testing::Robot("left", 0.8, 1.2, 1.2), testing::Robot("right", 0.8, 6.8, 1.2)};
  absl::StatusOr<FleetPlan> plan = PlanFleet(engine, testing::SourceOfMap(map, "rooms"), f);
  ASSERT_TRUE(plan.ok()) << plan.status();
  v1::PlanFleetResponse proto;
  FleetPlanToProto(*plan, &proto);
  ASSERT_EQ(proto.robots_size(), 2);
  EXPECT_EQ(proto.robots(1).id(), "right");
  EXPECT_EQ(proto.robots(0).plan().path_size(),
            static_cast<int>(plan->robots[0].result.plan.path.size()));
  EXPECT_EQ(proto.safety().closest_pair_size(), 2);
  absl::StatusOr<FleetPlan> back = FleetPlanFromProto(proto);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->robots.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const FleetRobotPlan& got = back->robots[i];
    const FleetRobotPlan& want = plan->robots[i];
    EXPECT_EQ(got.id, want.id);
    EXPECT_EQ(got.assigned_cells, want.assigned_cells);
    EXPECT_EQ(got.area_share, want.area_share);
    EXPECT_EQ(got.duration_s, want.duration_s);
    EXPECT_EQ(got.idle, want.idle);
    EXPECT_EQ(got.result.plan.path.size(), want.result.plan.path.size());
    EXPECT_EQ(got.result.plan.sweeps.size(), want.result.plan.sweeps.size());
  }
  EXPECT_EQ(back->makespan_s, plan->makespan_s);
  EXPECT_EQ(back->lower_bound_s, plan->lower_bound_s);
  EXPECT_EQ(back->gap, plan->gap);
  EXPECT_EQ(back->cover_cells, plan->cover_cells);
  EXPECT_EQ(back->covered_cells, plan->covered_cells);
  EXPECT_EQ(back->rebalance_rounds, plan->rebalance_rounds);
  EXPECT_GT(plan->floor.reachable_area_m2, 0.0);
  EXPECT_EQ(back->floor.reachable_area_m2, plan->floor.reachable_area_m2);
  EXPECT_EQ(back->floor.swept_reachable_ratio, plan->floor.swept_reachable_ratio);
  EXPECT_EQ(back->floor.missed_reachable_m2, plan->floor.missed_reachable_m2);
  EXPECT_EQ(back->termination.reason, plan->termination.reason);
  EXPECT_EQ(back->termination.detail, plan->termination.detail);
  EXPECT_EQ(back->safety.closest_approach_m, plan->safety.closest_approach_m);
  EXPECT_EQ(back->safety.closest_pair[1], plan->safety.closest_pair[1]);
  EXPECT_EQ(back->safety.conflicts.size(), plan->safety.conflicts.size());
  // Again to the proto: the same bytes.
  v1::PlanFleetResponse again;
  FleetPlanToProto(*back, &again);
  EXPECT_EQ(again.robots(0).plan().sweeps_size(), proto.robots(0).plan().sweeps_size());
  EXPECT_EQ(again.safety().SerializeAsString(), proto.safety().SerializeAsString());
}

}  // namespace
}  // namespace covplan
