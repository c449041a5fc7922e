#include "server/fleet_handlers.h"

#include "server/solve_call.h"

#include <memory>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api/convert.h"
#include "api/convert_fleet.h"
#include "planner/common/status_macros.h"
#include "planner/fleet/fleet_planner.h"
#include "server/request_limits.h"
#include "server/solve_inputs.h"

namespace covplan {
namespace {

// The log line's detail of a fleet plan.
std::string FleetDetail(const v1::PlanFleetResponse& response) {
  return absl::StrFormat("mission=%s robots=%d makespan_s=%.1f gap=%.3f covered=%d/%d",
                         QuotePrefix(response.mission_id(), 20), response.robots_size(),
                         response.makespan_s(), response.gap(), response.covered_cells(),
                         response.cover_cells());
}

}  // namespace

grpc::ServerUnaryReactor* FleetHandlers::PlanFleet(grpc::CallbackServerContext* context,
                                                   const v1::PlanFleetRequest* request,
                                                   v1::PlanFleetResponse* response) {
  return ServeSolve(
      gate_, admission_, context, "PlanFleet", *request,
      [this](const CallInfo& call) { return admission_->AdmitPlan(call, /*likely_hit=*/false); },
      [this, request, response](const CallInfo& call, const StopToken& cancel,
                                std::string* detail) {
        absl::Status status = RunPlanFleet(call, *request, cancel, response);
        if (status.ok()) *detail = FleetDetail(*response);
        return status;
      });
}

absl::Status FleetHandlers::RunPlanFleet(const CallInfo& call, const v1::PlanFleetRequest& request,
                                         const StopToken& cancel, v1::PlanFleetResponse* response) {
  const absl::Time start = absl::Now();
  if (admission_->drain_cut())
    return absl::UnavailableError("server is shutting down; retry on another");
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  ASSIGN_OR_RETURN(FleetRequest fleet, FleetRequestFromProto(request));
  ASSIGN_OR_RETURN(const CallBudget budget,
                   BudgetFor(options_, call, request.plan().time_limit_s(), cancel, start));
  fleet.base.common.time_limit_s = budget.time_limit_s;
  fleet.base.common.stop = budget.stop;
  ASSIGN_OR_RETURN(const MapSource source,
                   PlanMapSource(store_, options_.limits, call, request.plan()));
  absl::StatusOr<FleetPlan> plan = covplan::PlanFleet(*engine_, source, fleet);
  if (!plan.ok()) {
    const absl::Status& s = plan.status();
    if (IsStop(s) && admission_->drain_cut()) {
      return absl::UnavailableError(
          "server shut down before a fleet plan was found; retry on another");
    }
    return IsStop(s) ? StoppedStatus(s, cancel, call, start, options_.max_request_time) : s;
  }
  FleetPlanToProto(*plan, response);
  RetainRobotPlans(call, request, fleet, source.map_id, &*plan, response);
  if (admission_->drain_cut() && response->termination().limit() == v1::LIMIT_CANCELLED) {
    response->mutable_termination()->set_detail(absl::StrCat(
        "cut short by the server's drain (shutting down); ", response->termination().detail()));
  }
  metrics_->RecordSolve(absl::ToDoubleSeconds(absl::Now() - start),
                        plan->termination.limit_reached());
  return absl::OkStatus();
}

void FleetHandlers::RetainRobotPlans(const CallInfo& call, const v1::PlanFleetRequest& request,
                                     const FleetRequest& fleet, const std::string& map_id,
                                     FleetPlan* plan, v1::PlanFleetResponse* response) {
  FleetMission mission;
  mission.mission_id = NewMissionId(call.tenant_tag);
  mission.map_id = map_id;
  const bool stored_map = request.plan().map_ref_case() == v1::PlanRequest::kMapId;
  for (size_t i = 0; i < plan->robots.size(); ++i) {
    FleetRobotPlan& rp = plan->robots[i];
    // As a Plan retains its plan: the robot's own request, its part of the
    // site as the coverage area (its sweeps are what it has to cover).
    auto retained = std::make_shared<RetainedPlan>();
    retained->plan_id = NewPlanId(call.tenant_tag);
    retained->map_id = map_id;
    retained->plan = std::move(rp.result.plan);
    retained->area = std::move(rp.result.area);
    retained->request = fleet.RobotRequest(i);
    retained->request.common.stop = StopToken();  // the call's token ends with the call
    // FleetPlanToProto wrote the plan; add what only the retained plan knows.
    v1::PlanResponse* out = response->mutable_robots(static_cast<int>(i))->mutable_plan();
    RetainedPlanFieldsToProto(*retained, out);
    // An idle robot's plan (no area) could not be rebuilt after a restart.
    if (stored_map && retained->area != nullptr) {
      archive_->Persist(FleetRobotPlanRequest(request, static_cast<int>(i)), *out);
    }
    mission.robot_ids.push_back(rp.id);
    mission.plan_ids.push_back(retained->plan_id);
    archive_->Put(std::move(retained));
  }
  archive_->PublishRetainedCount();
  response->set_mission_id(mission.mission_id);
  missions_->Put(std::move(mission));
}

}  // namespace covplan
