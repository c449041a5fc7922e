// Fleets at the proto edge (convert.h is the rest of it): a PlanFleetRequest
// in as a FleetRequest (planner/fleet/fleet_request.h), a FleetPlan out as a
// PlanFleetResponse, and the inverses for clients. The base plan request
// and every robot's model and battery go through the single-robot
// conversion (PlanRequestFromProto), so a fleet accepts and refuses exactly
// what Plan does; errors are InvalidArgument naming the field
// ("plan.time_limit_s ...", "robots[1].robot.tool_width_m ...",
// "robots[1].id: ...", "division: unknown value 7").
//
//   ASSIGN_OR_RETURN(FleetRequest fleet, FleetRequestFromProto(request));
//   ASSIGN_OR_RETURN(FleetPlan plan, PlanFleet(engine, source, fleet));
//   v1::PlanFleetResponse response;
//   FleetPlanToProto(plan, &response);  // then each robot plan's plan_id, map_id, zones
//
// Thread-safety: stateless free functions, safe to call concurrently.
#ifndef COVPLAN_API_CONVERT_FLEET_H_
#define COVPLAN_API_CONVERT_FLEET_H_

#include "absl/status/statusor.h"
#include "api/convert.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/fleet/fleet_request.h"

namespace covplan {

// The fleet request of a PlanFleetRequest, validated (FleetRequest::Validate).
// Its base's robot is robots[0]'s model and its battery is unset (each robot
// brings its own); a request without a time limit gets
// CommonOptions::kDefaultTimeLimitS, as PlanRequestFromProto gives.
absl::StatusOr<FleetRequest> FleetRequestFromProto(const v1::PlanFleetRequest& request,
                                                   const LocalPlanOptions& local = {});

// The PlanRequest robot `i` plans with, on the wire: the request's base with
// that robot's model and battery (the proto form of
// FleetRequest::RobotRequest(i)). A server keeps it as the origin of the
// robot's plan. `i` must index request.robots.
v1::PlanRequest FleetRobotPlanRequest(const v1::PlanFleetRequest& request, int i);

// The inverse for a client: `request`'s robots, division and clearance
// around `base`, the wire form of request.base (a PlanRequest has no
// conversion back to the proto). The cover mask has no wire form.
void FleetRequestToProto(const FleetRequest& request, const v1::PlanRequest& base,
                         v1::PlanFleetRequest* out);
void FleetRobotToProto(const FleetRobot& robot, v1::FleetRobot* out);

v1::FleetDivision FleetDivisionToProto(FleetDivision division);
absl::StatusOr<FleetDivision> FleetDivisionFromProto(v1::FleetDivision division);

// Everything but mission_id and, in each robot's plan, plan_id, map_id and
// the zones (as PlanToProto).
void FleetPlanToProto(const FleetPlan& plan, v1::PlanFleetResponse* out);
// The inverse (e.g. to render a server's answer): each robot's plan by
// PlanFromProto, without its coverage area. InvalidArgument on an
// inconsistent response.
absl::StatusOr<FleetPlan> FleetPlanFromProto(const v1::PlanFleetResponse& response);

}  // namespace covplan

#endif  // COVPLAN_API_CONVERT_FLEET_H_
