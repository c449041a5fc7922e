#include "planner/fleet/fleet_request.h"

#include <cmath>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace covplan {

const char* FleetDivisionName(FleetDivision d) {
  switch (d) {
    case FleetDivision::kMakespan:
      return "makespan";
    case FleetDivision::kEqualArea:
      return "equal_area";
  }
  return "unknown";
}

namespace {

absl::Status Prefixed(const absl::Status& s, const std::string& prefix) {
  if (s.ok()) return s;
  return absl::Status(s.code(), absl::StrCat(prefix, s.message()));
}

}  // namespace

absl::Status FleetRequest::Validate() const {
  if (robots.empty()) {
    return absl::InvalidArgumentError("robots: a fleet plan needs at least one robot");
  }
  if (static_cast<int>(robots.size()) > kMaxRobots) {
    return absl::InvalidArgumentError(
        absl::StrFormat("robots: at most %d robots per fleet, got %d", kMaxRobots, robots.size()));
  }
  if (!drive_mask.empty() && cover_mask.empty()) {
    return absl::InvalidArgumentError("drive_mask: given without a cover mask");
  }
  std::map<std::string, size_t> seen;
  for (size_t i = 0; i < robots.size(); ++i) {
    const FleetRobot& r = robots[i];
    const std::string field = absl::StrFormat("robots[%d]", i);
    if (r.id.empty()) return absl::InvalidArgumentError(field + ".id: must not be empty");
    if (r.id.size() > 64) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s.id: at most 64 characters, got %d", field, r.id.size()));
    }
    if (auto [it, fresh] = seen.emplace(r.id, i); !fresh) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s.id: '%s' is already the id of robots[%d]; ids must be unique", field,
                          r.id, it->second));
    }
    if (absl::Status s = r.robot.Validate(); !s.ok()) return Prefixed(s, field + ".");
    if (r.robot.tool_width_m != robots[0].robot.tool_width_m) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s.robot.tool_width_m: %g differs from robots[0]'s %g; the robots of one fleet plan "
          "share one tool width (plan robots with other tools as another fleet)",
          field, r.robot.tool_width_m, robots[0].robot.tool_width_m));
    }
    if (r.battery.has_value()) {
      if (absl::Status s = r.battery->Validate(); !s.ok()) return Prefixed(s, field + ".");
    }
    if (!std::isfinite(r.recharge_s) || r.recharge_s < 0.0 || r.recharge_s > 1e6) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s.recharge_s: must be in [0, 1e6] seconds, got %g", field, r.recharge_s));
    }
  }
  if (!std::isfinite(clearance_m) || clearance_m < 0.0 || clearance_m > 1e3) {
    return absl::InvalidArgumentError(
        absl::StrFormat("clearance_m: must be in [0, 1000] metres, got %g", clearance_m));
  }
  return absl::OkStatus();
}

PlanRequest FleetRequest::RobotRequest(size_t i) const {
  PlanRequest r = base;
  r.common.robot = robots[i].robot;
  r.battery = robots[i].battery;
  return r;
}

}  // namespace covplan
