#include "planner/energy/battery.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

absl::Status NonNegative(double v, const char* field) {
  if (!std::isfinite(v) || v < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s must be a finite value >= 0, got %g", field, v));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status EnergyModel::Validate() const {
  for (auto [v, field] : {std::pair{per_metre, "battery.energy.per_metre"},
                          std::pair{per_turn, "battery.energy.per_turn"},
                          std::pair{per_second, "battery.energy.per_second"}}) {
    absl::Status s = NonNegative(v, field);
    if (!s.ok()) return s;
  }
  if (per_metre == 0.0 && per_turn == 0.0 && per_second == 0.0) {
    return absl::InvalidArgumentError(
        "battery.energy: every coefficient is 0; the path would cost nothing");
  }
  return absl::OkStatus();
}

absl::Status BatteryOptions::Validate() const {
  if (!std::isfinite(capacity) || capacity <= 0.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("battery.capacity must be a finite value > 0, got %g", capacity));
  }
  if (!std::isfinite(reserve) || reserve < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("battery.reserve must be a finite value >= 0, got %g", reserve));
  }
  if (reserve >= capacity) {
    return absl::InvalidArgumentError(
        absl::StrFormat("battery.reserve (%g) must be below battery.capacity (%g): nothing would "
                        "be left to drive on",
                        reserve, capacity));
  }
  if (!atomic_units.empty() && !interruptible_units) {
    return absl::InvalidArgumentError(
        "battery.atomic_units only makes sense with battery.interruptible_units (all units are "
        "atomic otherwise)");
  }
  if (!std::isfinite(station.x) || !std::isfinite(station.y) || !std::isfinite(station.theta)) {
    return absl::InvalidArgumentError("battery.station must have finite x, y and theta");
  }
  return energy.Validate();
}

bool BatteryOptions::IsAtomic(int tag) const {
  if (!interruptible_units) return true;
  return std::find(atomic_units.begin(), atomic_units.end(), tag) != atomic_units.end();
}

double SegmentEnergy(double heading_before, const Waypoint& a, const Waypoint& b,
                     const EnergyModel& model, const RobotModel& robot) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  double e = model.per_metre * len;
  if (model.per_second != 0.0) e += model.per_second * robot.StraightTime(len);
  const double change = HeadingChange(heading_before, b.theta);
  if (change > kTurnEpsilonRad) {
    e += model.per_turn;
    if (model.per_second != 0.0) e += model.per_second * robot.TurnTime(change);
  }
  return e;
}

double PathEnergy(const std::vector<Waypoint>& path, size_t lo, size_t hi, const EnergyModel& model,
                  const RobotModel& robot) {
  double e = 0.0;
  for (size_t i = lo + 1; i <= hi && i < path.size(); ++i) {
    e += SegmentEnergy(path[i - 1].theta, path[i - 1], path[i], model, robot);
  }
  return e;
}

}  // namespace covplan
