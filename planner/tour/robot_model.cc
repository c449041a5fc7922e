#include "planner/tour/robot_model.h"

#include <cmath>

#include "absl/strings/str_format.h"

namespace covplan {
namespace {

absl::Status CheckRange(const char* name, double v, double lo, double hi, const char* unit) {
  if (!(v >= lo && v <= hi)) {  // also rejects NaN
    return absl::InvalidArgumentError(
        absl::StrFormat("%s must be between %g and %g %s, got %g", name, lo, hi, unit, v));
  }
  return absl::OkStatus();
}

absl::Status CheckPose(const char* name, const std::optional<Pose2>& p) {
  if (p && (!std::isfinite(p->x) || !std::isfinite(p->y) || !std::isfinite(p->theta))) {
    return absl::InvalidArgumentError(absl::StrFormat("%s must have finite x, y and theta", name));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status RobotModel::Validate() const {
  for (absl::Status s :
       {CheckRange("robot.tool_width_m", tool_width_m, kMinToolWidth, kMaxToolWidth, "m"),
        CheckRange("robot.max_speed_mps", max_speed_mps, kMinSpeed, kMaxSpeed, "m/s"),
        CheckRange("robot.acceleration_mps2", acceleration_mps2, kMinAcceleration, kMaxAcceleration,
                   "m/s^2"),
        CheckRange("robot.turn_rate_deg_s", turn_rate_deg_s, kMinTurnRate, kMaxTurnRate, "deg/s"),
        CheckPose("robot.start", start), CheckPose("robot.end", end)}) {
    if (!s.ok()) return s;
  }
  return absl::OkStatus();
}

double RobotModel::StraightTime(double length_m) const {
  if (!(length_m > 0.0)) return 0.0;
  const double v = max_speed_mps, a = acceleration_mps2;
  // Distance needed to reach top speed and stop again.
  const double ramp = v * v / a;
  if (length_m <= ramp) return 2.0 * std::sqrt(length_m / a);  // triangular profile
  return 2.0 * v / a + (length_m - ramp) / v;                  // trapezoidal profile
}

double RobotModel::TurnTime(double angle_rad) const {
  double a = std::fmod(std::abs(angle_rad), 2.0 * M_PI);
  if (a > M_PI) a = 2.0 * M_PI - a;
  return a / (turn_rate_deg_s * M_PI / 180.0);
}

double HeadingChange(double from_rad, double to_rad) {
  double d = std::abs(to_rad - from_rad);
  if (!(d < 2.0 * M_PI)) d = std::fmod(d, 2.0 * M_PI);  // fmod is the identity below 2 pi, and slow
  return d > M_PI ? 2.0 * M_PI - d : d;
}

}  // namespace covplan
