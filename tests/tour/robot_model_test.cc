#include "planner/tour/robot_model.h"

#include <cmath>
#include <vector>

#include "gtest/gtest.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

TEST(RobotModel, ShortSegmentNeverReachesTopSpeed) {
  RobotModel robot;  // 1 m/s, 0.5 m/s^2: needs 2 m to reach top speed and stop
  // 1 m: accelerate 0.5 m, decelerate 0.5 m; t = 2*sqrt(2*0.5/0.5) = 2*sqrt(2).
  EXPECT_NEAR(robot.StraightTime(1.0), 2.0 * std::sqrt(2.0), 1e-12);
  // Exactly the ramp distance: 2 s up, 2 s down.
  EXPECT_NEAR(robot.StraightTime(2.0), 4.0, 1e-12);
}

TEST(RobotModel, LongSegmentCruises) {
  RobotModel robot;
  // 10 m: 2 m ramps (4 s) + 8 m at 1 m/s.
  EXPECT_NEAR(robot.StraightTime(10.0), 12.0, 1e-12);
  robot.max_speed_mps = 2.0;
  robot.acceleration_mps2 = 1.0;
  // ramps: 4 m in 4 s; cruise 6 m at 2 m/s = 3 s.
  EXPECT_NEAR(robot.StraightTime(10.0), 7.0, 1e-12);
}

TEST(RobotModel, TurnTimes) {
  RobotModel robot;  // 30 deg/s
  EXPECT_NEAR(robot.TurnTime(M_PI / 2), 3.0, 1e-12);
  EXPECT_NEAR(robot.TurnTime(M_PI), 6.0, 1e-12);
  EXPECT_NEAR(robot.TurnTime(-M_PI / 2), 3.0, 1e-12);
  EXPECT_NEAR(robot.TurnTime(3 * M_PI / 2), 3.0, 1e-12);  // the short way round
  EXPECT_NEAR(HeadingChange(0.1, 2 * M_PI - 0.1), 0.2, 1e-12);
}

TEST(RobotModel, ValidateRejectsBadValues) {
  for (double bad : {0.0, -1.0, static_cast<double>(NAN), static_cast<double>(INFINITY)}) {
    RobotModel r;
    r.max_speed_mps = bad;
    EXPECT_EQ(r.Validate().code(), absl::StatusCode::kInvalidArgument) << bad;
    RobotModel w;
    w.tool_width_m = bad;
    EXPECT_EQ(w.Validate().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(w.Validate().message().find("robot.tool_width_m"), std::string::npos);
  }
  RobotModel p;
  p.start = Pose2{NAN, 0, 0};
  EXPECT_EQ(p.Validate().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(RobotModel().Validate().ok());
}

// Positive but absurd values would make every drive time infinite or zero.
TEST(RobotModel, ValidateRejectsValuesOutsideThePhysicalRange) {
  RobotModel slow;
  slow.acceleration_mps2 = 1e-300;
  EXPECT_EQ(slow.Validate().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(slow.Validate().message().find("acceleration"), std::string::npos);
  RobotModel frozen;
  frozen.turn_rate_deg_s = 5e-324;
  EXPECT_NE(frozen.Validate().message().find("robot.turn_rate_deg_s"), std::string::npos);
  RobotModel rocket;
  rocket.max_speed_mps = 1e300;
  EXPECT_NE(rocket.Validate().message().find("robot.max_speed_mps"), std::string::npos);
  // The bounds themselves are accepted and give finite times.
  RobotModel edge;
  edge.max_speed_mps = RobotModel::kMinSpeed;
  edge.acceleration_mps2 = RobotModel::kMinAcceleration;
  edge.turn_rate_deg_s = RobotModel::kMinTurnRate;
  ASSERT_TRUE(edge.Validate().ok());
  EXPECT_TRUE(std::isfinite(edge.StraightTime(1e6)));
  EXPECT_TRUE(std::isfinite(edge.TurnTime(M_PI)));
}

TEST(PathTiming, LShapedPathWithTurns) {
  RobotModel robot;
  // Facing +x, drive 10 m east, turn 90 deg, drive 1 m north, then face west.
  PolylineTiming t = TimePolyline(robot, {{0, 0}, {10, 0}, {10, 1}}, 0.0, M_PI);
  EXPECT_EQ(t.turns, 2);
  EXPECT_NEAR(t.turn_time_s, 3.0 + 3.0, 1e-9);
  EXPECT_NEAR(t.length_m, 11.0, 1e-12);
  EXPECT_NEAR(t.time_s, 12.0 + 2.0 * std::sqrt(2.0) + 6.0, 1e-9);
}

TEST(PathTiming, UTurnAndZeroLengthSegments) {
  RobotModel robot;
  PolylineTiming t = TimePolyline(robot, {{0, 0}, {0, 0}, {-2, 0}}, 0.0, std::nullopt);
  EXPECT_EQ(t.turns, 1);
  EXPECT_NEAR(t.time_s, 6.0 + 4.0, 1e-9);  // 180 deg turn + 2 m ramp-only segment
}

// Waypoints as plans carry them: each holds the heading of the segment
// that ends there.
std::vector<Waypoint> Path(const std::vector<Pose2>& poses) {
  std::vector<Waypoint> path;
  for (const Pose2& p : poses) {
    Waypoint w;
    w.x = p.x, w.y = p.y, w.theta = p.theta;
    w.kind = path.empty() ? SegmentKind::kStart : SegmentKind::kCoverage;
    path.push_back(w);
  }
  return path;
}

TEST(ArrivalTimes, HandWorkedPathWithTurnsAndARecharge) {
  RobotModel robot;  // 1 m/s, 0.5 m/s^2, 30 deg/s
  const std::vector<Waypoint> path =
      Path({{0, 0, 0}, {10, 0, 0}, {10, 1, M_PI / 2}, {0, 1, M_PI}, {0, 1, M_PI}});
  std::vector<double> t = ArrivalTimes(robot, path);
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[0], 0.0);
  EXPECT_NEAR(t[1], 12.0, 1e-9);                               // 10 m
  EXPECT_NEAR(t[2], 12.0 + 3.0 + 2.0 * std::sqrt(2.0), 1e-9);  // turn 90 deg, 1 m
  EXPECT_NEAR(t[3], t[2] + 3.0 + 12.0, 1e-9);                  // turn 90 deg, 10 m
  EXPECT_NEAR(t[4], t[3], 1e-12);                              // no move, no turn
  // The last entry is the polyline's drive time from the first heading.
  EXPECT_NEAR(t[4], TimePolyline(robot, {{0, 0}, {10, 0}, {10, 1}, {0, 1}}, 0.0, M_PI).time_s,
              1e-9);
  // Two cycles: the robot waits at the station after the first (waypoint
  // 1) and not after the last.
  std::vector<ChargeCycle> cycles(2);
  cycles[0].last_waypoint = 1;
  cycles[1].first_waypoint = 1;
  cycles[1].last_waypoint = 4;
  const std::vector<double> charged = ArrivalTimes(robot, path, cycles, /*recharge_s=*/100.0);
  EXPECT_NEAR(charged[1], t[1], 1e-12);
  for (size_t i = 2; i < t.size(); ++i) EXPECT_NEAR(charged[i], t[i] + 100.0, 1e-9) << i;
}

}  // namespace
}  // namespace covplan
