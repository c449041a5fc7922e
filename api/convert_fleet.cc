#include "api/convert_fleet.h"

#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

absl::Status Prefixed(const absl::Status& status, absl::string_view prefix) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

void PoseToProto(const Pose2& pose, v1::Pose* out) {
  out->set_x(pose.x);
  out->set_y(pose.y);
  out->set_theta(pose.theta);
}

void RobotModelToProto(const RobotModel& robot, v1::RobotModel* out) {
  out->set_tool_width_m(robot.tool_width_m);
  out->set_max_speed_mps(robot.max_speed_mps);
  out->set_acceleration_mps2(robot.acceleration_mps2);
  out->set_turn_rate_deg_s(robot.turn_rate_deg_s);
  if (robot.start) PoseToProto(*robot.start, out->mutable_start());
  if (robot.end) PoseToProto(*robot.end, out->mutable_end());
}

void BatteryToProto(const BatteryOptions& battery, v1::Battery* out) {
  out->set_capacity(battery.capacity);
  PoseToProto(battery.station, out->mutable_station());
  out->set_reserve(battery.reserve);
  out->mutable_energy()->set_per_metre(battery.energy.per_metre);
  out->mutable_energy()->set_per_turn(battery.energy.per_turn);
  out->mutable_energy()->set_per_second(battery.energy.per_second);
  out->set_interruptible_units(battery.interruptible_units);
  for (int unit : battery.atomic_units) out->add_atomic_units(unit);
}

// The base request converted on its own: a placeholder robot (a valid
// model, so that only the base's own fields can be refused here) and no
// battery; each robot's model and battery are converted with the robot.
absl::StatusOr<PlanRequest> BaseFromProto(const v1::PlanFleetRequest& request,
                                          const LocalPlanOptions& local) {
  v1::PlanRequest base = request.plan();
  base.clear_map_ref();  // not read by the conversion; no need to keep a copy
  base.clear_battery();
  base.clear_robot();
  base.mutable_robot()->set_tool_width_m(1.0);
  absl::StatusOr<PlanRequest> converted = PlanRequestFromProto(base, local);
  if (!converted.ok()) return Prefixed(converted.status(), "plan.");
  converted->battery.reset();
  return converted;
}

// Robot `i`'s model and battery through the single-robot conversion: a
// request holding only them, so every error names one of their fields.
absl::StatusOr<FleetRobot> RobotFromProto(const v1::FleetRobot& robot, int i) {
  v1::PlanRequest own;
  *own.mutable_robot() = robot.robot();
  if (robot.has_battery()) *own.mutable_battery() = robot.battery();
  absl::StatusOr<PlanRequest> converted = PlanRequestFromProto(own);
  if (!converted.ok()) return Prefixed(converted.status(), absl::StrFormat("robots[%d].", i));
  FleetRobot out;
  out.id = robot.id();
  out.robot = converted->common.robot;
  out.battery = converted->battery;
  out.recharge_s = robot.recharge_s();
  return out;
}

void SafetyToProto(const FleetSafety& safety, v1::FleetSafety* out) {
  out->set_clearance_m(safety.clearance_m);
  out->set_closest_approach_m(safety.closest_approach_m);
  out->set_closest_at_s(safety.closest_at_s);
  if (!safety.closest_pair[0].empty() || !safety.closest_pair[1].empty()) {
    out->add_closest_pair(safety.closest_pair[0]);
    out->add_closest_pair(safety.closest_pair[1]);
  }
  for (const FleetSafety::Conflict& c : safety.conflicts) {
    v1::FleetConflict* o = out->add_conflicts();
    o->set_start_s(c.start_s);
    o->set_end_s(c.end_s);
    o->set_min_distance_m(c.min_distance_m);
    o->set_robot_a(c.robot_a);
    o->set_robot_b(c.robot_b);
  }
  out->set_sample_step_s(safety.sample_step_s);
}

absl::StatusOr<FleetSafety> SafetyFromProto(const v1::FleetSafety& safety) {
  FleetSafety out;
  out.clearance_m = safety.clearance_m();
  out.closest_approach_m = safety.closest_approach_m();
  out.closest_at_s = safety.closest_at_s();
  if (safety.closest_pair_size() != 0 && safety.closest_pair_size() != 2) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "safety.closest_pair: two robot ids or none, got %d", safety.closest_pair_size()));
  }
  for (int i = 0; i < safety.closest_pair_size(); ++i) out.closest_pair[i] = safety.closest_pair(i);
  for (const v1::FleetConflict& c : safety.conflicts()) {
    out.conflicts.push_back({c.start_s(), c.end_s(), c.min_distance_m(), c.robot_a(), c.robot_b()});
  }
  out.sample_step_s = safety.sample_step_s();
  return out;
}

}  // namespace

v1::FleetDivision FleetDivisionToProto(FleetDivision division) {
  return division == FleetDivision::kEqualArea ? v1::FLEET_DIVISION_EQUAL_AREA
                                               : v1::FLEET_DIVISION_MAKESPAN;
}

absl::StatusOr<FleetDivision> FleetDivisionFromProto(v1::FleetDivision division) {
  switch (division) {
    case v1::FLEET_DIVISION_MAKESPAN:
      return FleetDivision::kMakespan;
    case v1::FLEET_DIVISION_EQUAL_AREA:
      return FleetDivision::kEqualArea;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("division: unknown value ", static_cast<int>(division)));
  }
}

absl::StatusOr<FleetRequest> FleetRequestFromProto(const v1::PlanFleetRequest& request,
                                                   const LocalPlanOptions& local) {
  FleetRequest out;
  ASSIGN_OR_RETURN(out.base, BaseFromProto(request, local));
  ASSIGN_OR_RETURN(out.division, FleetDivisionFromProto(request.division()));
  out.clearance_m = request.clearance_m();
  if (request.robots_size() > FleetRequest::kMaxRobots) {
    // Refused by Validate before converting thousands of robots.
    out.robots.resize(static_cast<size_t>(request.robots_size()));
    return out.Validate();
  }
  for (int i = 0; i < request.robots_size(); ++i) {
    ASSIGN_OR_RETURN(FleetRobot robot, RobotFromProto(request.robots(i), i));
    out.robots.push_back(std::move(robot));
  }
  RETURN_IF_ERROR(out.Validate());
  out.base.common.robot = out.robots[0].robot;
  return out;
}

v1::PlanRequest FleetRobotPlanRequest(const v1::PlanFleetRequest& request, int i) {
  v1::PlanRequest out = request.plan();
  const v1::FleetRobot& robot = request.robots(i);
  *out.mutable_robot() = robot.robot();
  if (robot.has_battery()) {
    *out.mutable_battery() = robot.battery();
  } else {
    out.clear_battery();
  }
  return out;
}

void FleetRobotToProto(const FleetRobot& robot, v1::FleetRobot* out) {
  out->set_id(robot.id);
  RobotModelToProto(robot.robot, out->mutable_robot());
  if (robot.battery) BatteryToProto(*robot.battery, out->mutable_battery());
  out->set_recharge_s(robot.recharge_s);
}

void FleetRequestToProto(const FleetRequest& request, const v1::PlanRequest& base,
                         v1::PlanFleetRequest* out) {
  *out->mutable_plan() = base;
  out->mutable_plan()->clear_robot();
  out->mutable_plan()->clear_battery();
  for (const FleetRobot& robot : request.robots) FleetRobotToProto(robot, out->add_robots());
  out->set_division(FleetDivisionToProto(request.division));
  out->set_clearance_m(request.clearance_m);
}

void FleetPlanToProto(const FleetPlan& plan, v1::PlanFleetResponse* out) {
  for (const FleetRobotPlan& rp : plan.robots) {
    v1::FleetRobotPlan* r = out->add_robots();
    r->set_id(rp.id);
    PlanToProto(rp.result.plan, r->mutable_plan());
    r->set_assigned_cells(static_cast<int32_t>(rp.assigned_cells));
    r->set_area_share(rp.area_share);
    r->set_duration_s(rp.duration_s);
    r->set_idle(rp.idle);
  }
  out->set_makespan_s(plan.makespan_s);
  out->set_lower_bound_s(plan.lower_bound_s);
  out->set_gap(plan.gap);
  out->set_sum_duration_s(plan.sum_duration_s);
  out->set_cover_cells(static_cast<int32_t>(plan.cover_cells));
  out->set_covered_cells(static_cast<int32_t>(plan.covered_cells));
  out->set_division(FleetDivisionToProto(plan.division));
  out->set_planning_ms(plan.planning_ms);
  out->set_rebalance_rounds(plan.rebalance_rounds);
  out->set_reachable_area_m2(plan.floor.reachable_area_m2);
  out->set_swept_reachable_ratio(plan.floor.swept_reachable_ratio);
  out->set_missed_reachable_m2(plan.floor.missed_reachable_m2);
  TerminationToProto(plan.termination, out->mutable_termination());
  SafetyToProto(plan.safety, out->mutable_safety());
}

absl::StatusOr<FleetPlan> FleetPlanFromProto(const v1::PlanFleetResponse& response) {
  FleetPlan out;
  for (int i = 0; i < response.robots_size(); ++i) {
    const v1::FleetRobotPlan& r = response.robots(i);
    FleetRobotPlan& rp = out.robots.emplace_back();
    rp.id = r.id();
    absl::StatusOr<CoveragePlan> plan = PlanFromProto(r.plan());
    if (!plan.ok()) return Prefixed(plan.status(), absl::StrFormat("robots[%d].plan: ", i));
    rp.result.plan = *std::move(plan);
    rp.assigned_cells = r.assigned_cells();
    rp.area_share = r.area_share();
    rp.duration_s = r.duration_s();
    rp.idle = r.idle();
  }
  ASSIGN_OR_RETURN(out.division, FleetDivisionFromProto(response.division()));
  out.makespan_s = response.makespan_s();
  out.lower_bound_s = response.lower_bound_s();
  out.gap = response.gap();
  out.sum_duration_s = response.sum_duration_s();
  out.cover_cells = response.cover_cells();
  out.covered_cells = response.covered_cells();
  out.planning_ms = response.planning_ms();
  out.rebalance_rounds = response.rebalance_rounds();
  out.floor.reachable_area_m2 = response.reachable_area_m2();
  out.floor.swept_reachable_ratio = response.swept_reachable_ratio();
  out.floor.missed_reachable_m2 = response.missed_reachable_m2();
  out.floor.swept_reachable_m2 = out.floor.reachable_area_m2 - out.floor.missed_reachable_m2;
  out.termination = TerminationFromProto(response.termination());
  ASSIGN_OR_RETURN(out.safety, SafetyFromProto(response.safety()));
  return out;
}

}  // namespace covplan
