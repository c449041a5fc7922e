// The robot's motion model (thesis Table 3.1): straight segments follow a
// trapezoidal velocity profile (start and stop at rest), turns are in place
// at a constant angular rate.
//
//   RobotModel robot;                       // thesis defaults
//   double t = robot.StraightTime(5.0) + robot.TurnTime(M_PI / 2);
//
// Thread-safety: plain value type.
#ifndef COVPLAN_PLANNER_TOUR_ROBOT_MODEL_H_
#define COVPLAN_PLANNER_TOUR_ROBOT_MODEL_H_

#include <optional>

#include "absl/status/status.h"

namespace covplan {

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;  // radians, map frame, 0 = +x
};

struct RobotModel {
  double tool_width_m = 0.8;
  double max_speed_mps = 1.0;
  double acceleration_mps2 = 0.5;
  double turn_rate_deg_s = 30.0;
  // Where the robot starts; default: the first rank's entry point.
  std::optional<Pose2> start;
  // Where the tour must end; default: back at the start.
  std::optional<Pose2> end;

  // Accepted ranges. Wide enough for any ground robot, narrow enough that
  // every drive time stays a finite, meaningful number (an acceleration of
  // 1e-300 m/s^2 is "positive" but makes every transition take forever).
  static constexpr double kMinToolWidth = 1e-3, kMaxToolWidth = 100.0;      // m
  static constexpr double kMinSpeed = 1e-2, kMaxSpeed = 100.0;              // m/s
  static constexpr double kMinAcceleration = 1e-3, kMaxAcceleration = 1e3;  // m/s^2
  static constexpr double kMinTurnRate = 0.1, kMaxTurnRate = 1e5;           // deg/s

  // InvalidArgument naming the field as the API does ("robot.tool_width_m")
  // when a value is outside its range or a pose is not finite.
  absl::Status Validate() const;

  // Time to drive a straight segment of `length` metres from rest to rest.
  double StraightTime(double length_m) const;
  // Time to turn in place by `angle` radians (sign ignored, wrapped to [0, pi]).
  double TurnTime(double angle_rad) const;
};

// Smallest absolute angle between two headings, in [0, pi].
double HeadingChange(double from_rad, double to_rad);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_ROBOT_MODEL_H_
