#include "api/convert_mission.h"

#include <string>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "api/convert_fleet.h"

namespace covplan {

absl::StatusOr<FleetRobot> JoiningRobotFromProto(const v1::FleetRobot& joining, int i) {
  // A fleet of this one robot: PlanFleet's own conversion and checks.
  v1::PlanFleetRequest fleet;
  *fleet.add_robots() = joining;
  absl::StatusOr<FleetRequest> converted = FleetRequestFromProto(fleet);
  if (converted.ok()) return std::move(converted->robots.front());
  const absl::Status& s = converted.status();
  const std::string field = absl::StrFormat("robots[%d].joining", i);
  absl::string_view message = s.message();
  if (absl::ConsumePrefix(&message, "robots[0]")) {
    return absl::Status(s.code(), absl::StrCat(field, message));
  }
  return absl::Status(s.code(), absl::StrCat(field, ": ", message));
}

Pose2 PoseFromProto(const v1::Pose& pose) { return Pose2{pose.x(), pose.y(), pose.theta()}; }

void MissionRedivisionToProto(const MissionRedivision& redivision, v1::UpdateMissionResponse* out) {
  v1::PlanFleetResponse fleet;
  FleetPlanToProto(redivision.plan, &fleet);
  out->mutable_robots()->Swap(fleet.mutable_robots());
  out->set_remaining_cells(redivision.remaining_cells);
  out->set_handed_over_cells(redivision.handed_over_cells);
  out->set_cut_off_cells(redivision.cut_off_cells);
  out->set_makespan_s(redivision.plan.makespan_s);
  out->set_planning_ms(redivision.plan.planning_ms);
}

}  // namespace covplan
