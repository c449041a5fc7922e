// Fleet missions at the proto edge (convert_fleet.h is the fleet plan): a
// joining robot of an UpdateMissionRequest in as a FleetRobot, through the
// same conversion as PlanFleet's robots, and a MissionRedivision
// (planner/fleet/mission.h) out as an UpdateMissionResponse.
//
//   ASSIGN_OR_RETURN(FleetRobot d, JoiningRobotFromProto(update.joining(), 3));
//   ...RedivideMission(...)...
//   MissionRedivisionToProto(redivision, &response);  // then plan ids, map id, zones
//
// Thread-safety: stateless free functions, safe to call concurrently.
#ifndef COVPLAN_API_CONVERT_MISSION_H_
#define COVPLAN_API_CONVERT_MISSION_H_

#include "absl/status/statusor.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/fleet/fleet_request.h"
#include "planner/fleet/mission.h"

namespace covplan {

// The robot `joining` of request.robots[i], converted as PlanFleet converts
// its robots; errors are InvalidArgument naming
// "robots[i].joining.<field>".
absl::StatusOr<FleetRobot> JoiningRobotFromProto(const v1::FleetRobot& joining, int i);

Pose2 PoseFromProto(const v1::Pose& pose);

// Everything but mission_id and, in each robot's plan, plan_id, map_id and
// the zones (as FleetPlanToProto).
void MissionRedivisionToProto(const MissionRedivision& redivision, v1::UpdateMissionResponse* out);

}  // namespace covplan

#endif  // COVPLAN_API_CONVERT_MISSION_H_
