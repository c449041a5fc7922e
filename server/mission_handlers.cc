#include "server/mission_handlers.h"

#include "server/solve_call.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "api/convert.h"
#include "api/convert_fleet.h"
#include "api/convert_mission.h"
#include "planner/common/status_macros.h"
#include "server/map_sources.h"
#include "server/request_limits.h"
#include "server/solve_inputs.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

absl::Status MissionNotFound(const std::string& mission_id) {
  return absl::NotFoundError(
      absl::StrCat("mission ", QuotePrefix(mission_id),
                   " not found (never planned here, another tenant's, or trimmed from the store "
                   "with old plans; plan the fleet again)"));
}

absl::Status Invalid(int j, absl::string_view field, absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrFormat("robots[%d].%s: %s", j, field, message));
}

// The log line's detail of a mission update.
std::string UpdateDetail(const v1::UpdateMissionResponse& response) {
  return absl::StrFormat("mission=%s robots=%d remaining=%d handed_over=%d makespan_s=%.1f",
                         QuotePrefix(response.mission_id(), 20), response.robots_size(),
                         response.remaining_cells(), response.handed_over_cells(),
                         response.makespan_s());
}

// The robot request.robots[j] (`u`) that joins; `taken`: its id is
// already a robot of the mission.
absl::StatusOr<FleetRobot> JoiningRobot(const v1::MissionRobotUpdate& u, int j, bool taken) {
  const std::string& id = u.robot_id();
  if (taken) {
    return Invalid(j, "robot_id",
                   absl::StrCat(QuotePrefix(id), " is taken: already a robot of the mission"));
  }
  if (!u.joining().id().empty() && u.joining().id() != id) {
    return Invalid(j, "joining.id", absl::StrCat("differs from robot_id ", QuotePrefix(id)));
  }
  if (u.stopped()) return Invalid(j, "stopped", "a joining robot cannot stop as it joins");
  if (u.has_progress()) return Invalid(j, "progress", "a joining robot has no plan yet");
  v1::FleetRobot wire = u.joining();
  wire.set_id(id);
  ASSIGN_OR_RETURN(FleetRobot robot, JoiningRobotFromProto(wire, j));
  if (!u.has_pose() && !robot.robot.start.has_value()) {
    return Invalid(j, "joining.robot.start", "required: where the joining robot stands");
  }
  return robot;
}

// RedivideMission names robots by their index in its list
// ("robots[3] ('d'): ..."); the caller knows them by the request's index.
absl::Status RenamedRobot(const absl::Status& status, const std::vector<int>& request_index) {
  absl::string_view message = status.message();
  if (!absl::ConsumePrefix(&message, "robots[")) return status;
  const size_t close = message.find(']');
  int k = -1;
  if (close == absl::string_view::npos || !absl::SimpleAtoi(message.substr(0, close), &k) ||
      k < 0 || k >= static_cast<int>(request_index.size()) || request_index[k] < 0) {
    return status;
  }
  return absl::Status(status.code(),
                      absl::StrFormat("robots[%d]%s", request_index[k], message.substr(close + 1)));
}

// `origin` with `robot`'s model and battery: the request a robot's new plan
// is persisted with.
v1::PlanRequest OriginFor(v1::PlanRequest origin, const FleetRobot& robot) {
  v1::FleetRobot wire;
  FleetRobotToProto(robot, &wire);
  *origin.mutable_robot() = wire.robot();
  if (wire.has_battery()) {
    *origin.mutable_battery() = wire.battery();
  } else {
    origin.clear_battery();
  }
  return origin;
}

}  // namespace

grpc::ServerUnaryReactor* MissionHandlers::UpdateMission(grpc::CallbackServerContext* context,
                                                         const v1::UpdateMissionRequest* request,
                                                         v1::UpdateMissionResponse* response) {
  return ServeSolve(
      gate_, admission_, context, "UpdateMission", *request,
      [this](const CallInfo& call) { return admission_->AdmitPlan(call, /*likely_hit=*/false); },
      [this, request, response](const CallInfo& call, const StopToken& cancel,
                                std::string* detail) {
        absl::Status status = RunUpdateMission(call, *request, cancel, response);
        if (status.ok()) *detail = UpdateDetail(*response);
        return status;
      });
}

grpc::ServerUnaryReactor* MissionHandlers::GetMission(grpc::CallbackServerContext* context,
                                                      const v1::GetMissionRequest* request,
                                                      v1::GetMissionResponse* response) {
  return ServeSolve(
      gate_, admission_, context, "GetMission", *request,
      [this](const CallInfo& call) { return admission_->Admit(call); },
      [this, request, response](const CallInfo& call, const StopToken& cancel,
                                std::string* detail) {
        absl::Status status = RunGetMission(call, *request, cancel, response);
        if (status.ok()) {
          *detail = absl::StrFormat(
              "%s covered=%d remaining=%d complete=%v", QuotePrefix(request->mission_id(), 20),
              response->covered_cells(), response->remaining_cells(), response->complete());
        }
        return status;
      });
}

absl::Status MissionHandlers::RunGetMission(const CallInfo& call,
                                            const v1::GetMissionRequest& request,
                                            const StopToken& cancel,
                                            v1::GetMissionResponse* response) {
  std::optional<FleetMission> mission;
  if (OwnsPlan(call.tenant_tag, request.mission_id()))
    mission = missions_->Get(request.mission_id());
  if (!mission.has_value()) return MissionNotFound(request.mission_id());
  response->set_mission_id(mission->mission_id);
  response->set_map_id(mission->map_id);
  std::vector<MissionRobot> robots;
  for (size_t i = 0; i < mission->robot_ids.size(); ++i) {
    v1::MissionRobotState* r = response->add_robots();
    r->set_robot_id(mission->robot_ids[i]);
    r->set_plan_id(mission->plan_ids[i]);
    r->set_stopped(mission->Stopped(i));
    MissionRobot& m = robots.emplace_back();
    m.robot.id = mission->robot_ids[i];
    m.active = !mission->Stopped(i);
    v1::PlanRequest origin;
    m.plan = archive_->Find(mission->plan_ids[i], cancel, &origin);
    if (m.plan == nullptr) {
      if (cancel.ShouldStop()) return absl::CancelledError("call cancelled");
      return absl::FailedPreconditionError(
          absl::StrFormat("robot %s's plan %s is no longer retained: no account",
                          QuotePrefix(mission->robot_ids[i]), QuotePrefix(mission->plan_ids[i])));
    }
    if (std::optional<v1::RobotProgress> p = progress_->Recorded(mission->plan_ids[i])) {
      absl::StatusOr<RobotProgress> progress = ProgressFromProto(*p);
      if (progress.ok()) m.progress = *progress;
    }
  }
  ASSIGN_OR_RETURN(MissionAccount account, AccountMission(robots));
  for (size_t i = 0; i < account.robots.size(); ++i) {
    v1::MissionRobotState* r = response->mutable_robots(static_cast<int>(i));
    r->set_covered_cells(account.robots[i].covered_cells);
    r->set_remaining_cells(account.robots[i].remaining_cells);
    r->set_cut_off_cells(account.robots[i].cut_off_cells);
  }
  response->set_covered_cells(account.covered_cells);
  response->set_remaining_cells(account.remaining_cells);
  response->set_cut_off_cells(account.cut_off_cells);
  response->set_complete(account.complete);
  return absl::OkStatus();
}

absl::Status MissionHandlers::RunUpdateMission(const CallInfo& call,
                                               const v1::UpdateMissionRequest& request,
                                               const StopToken& cancel,
                                               v1::UpdateMissionResponse* response) {
  const absl::Time start = absl::Now();
  if (admission_->drain_cut())
    return absl::UnavailableError("server is shutting down; retry on another");
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  std::optional<FleetMission> mission;
  if (OwnsPlan(call.tenant_tag, request.mission_id()))
    mission = missions_->Get(request.mission_id());
  if (!mission.has_value()) return MissionNotFound(request.mission_id());
  Roster roster;
  RETURN_IF_ERROR(BuildRoster(*mission, request, cancel, &roster));
  // The mission's own budget (its PlanFleet's time limit), within the call's.
  ASSIGN_OR_RETURN(const CallBudget budget,
                   BudgetFor(options_, call, roster.base.common.time_limit_s, cancel, start));
  roster.base.common.time_limit_s = budget.time_limit_s;
  roster.base.common.stop = budget.stop;
  // A stored map as PlanFleet resolves it (owner, not deleted); an inline
  // map only while its artifacts are cached (it was not kept).
  MapSource source;
  if (roster.origin.map_ref_case() == v1::PlanRequest::kMapId) {
    ASSIGN_OR_RETURN(source, PlanMapSource(store_, options_.limits, call, roster.origin));
  } else {
    source = MapSourceFor(store_, options_.limits, mission->map_id, nullptr);
  }
  absl::StatusOr<MissionRedivision> redivision =
      RedivideMission(*engine_, source, roster.base, roster.robots, MissionOptions{});
  if (!redivision.ok()) {
    const absl::Status& s = redivision.status();
    if (IsStop(s) && admission_->drain_cut()) {
      return absl::UnavailableError(
          "server shut down before the mission was redivided; retry on another");
    }
    return IsStop(s) ? StoppedStatus(s, cancel, call, start, options_.max_request_time)
                     : RenamedRobot(s, roster.request_index);
  }
  RETURN_IF_ERROR(KeepPlans(call, *mission, roster, &*redivision, response));
  metrics_->RecordSolve(absl::ToDoubleSeconds(absl::Now() - start),
                        redivision->plan.termination.limit_reached());
  return absl::OkStatus();
}

absl::Status MissionHandlers::BuildRoster(const FleetMission& mission,
                                          const v1::UpdateMissionRequest& request,
                                          const StopToken& stop, Roster* roster) {
  std::map<std::string, int> in_mission;
  for (size_t i = 0; i < mission.robot_ids.size(); ++i) {
    in_mission[mission.robot_ids[i]] = static_cast<int>(i);
  }
  std::vector<int> update_of(mission.robot_ids.size(), -1);
  std::map<std::string, int> named;
  std::vector<std::pair<int, FleetRobot>> joining;
  for (int j = 0; j < request.robots_size(); ++j) {
    const v1::MissionRobotUpdate& u = request.robots(j);
    const std::string& id = u.robot_id();
    if (id.empty()) return Invalid(j, "robot_id", "required");
    if (auto [it, fresh] = named.emplace(id, j); !fresh) {
      return Invalid(
          j, "robot_id",
          absl::StrFormat("%s is named twice (also robots[%d])", QuotePrefix(id), it->second));
    }
    auto it = in_mission.find(id);
    if (u.has_joining()) {
      ASSIGN_OR_RETURN(FleetRobot robot, JoiningRobot(u, j, it != in_mission.end()));
      joining.emplace_back(j, std::move(robot));
      continue;
    }
    if (it == in_mission.end()) {
      return Invalid(
          j, "robot_id",
          absl::StrCat(QuotePrefix(id), " is not a robot of mission ",
                       QuotePrefix(mission.mission_id), " (a robot that joins needs `joining`)"));
    }
    if (mission.Stopped(it->second) && !u.stopped()) {
      return Invalid(j, "robot_id",
                     absl::StrCat(QuotePrefix(id),
                                  " stopped for good earlier; it may join again under a new id"));
    }
    update_of[it->second] = j;
  }
  for (size_t i = 0; i < mission.robot_ids.size(); ++i) {
    if (mission.Stopped(i)) continue;  // its remainder was handed over before
    v1::PlanRequest origin;
    std::shared_ptr<const RetainedPlan> plan = archive_->Find(mission.plan_ids[i], stop, &origin);
    if (plan == nullptr) {
      return absl::FailedPreconditionError(
          absl::StrFormat("robot %s's plan %s is no longer retained; plan the fleet again",
                          QuotePrefix(mission.robot_ids[i]), QuotePrefix(mission.plan_ids[i])));
    }
    if (roster->robots.empty()) {
      roster->base = plan->request;
      roster->origin = origin;
    }
    MissionRobot r;
    r.robot.id = mission.robot_ids[i];
    r.robot.robot = plan->request.common.robot;
    r.robot.battery = plan->request.battery;
    // Without an end pose a robot returns to where it started the mission,
    // not to where it stands now.
    if (!r.robot.robot.end.has_value()) r.robot.robot.end = r.robot.robot.start;
    r.plan = plan;
    const int j = update_of[i];
    std::optional<v1::RobotProgress> progress;
    if (j >= 0 && request.robots(j).has_progress()) {
      progress = request.robots(j).progress();
    } else {
      progress = progress_->Recorded(mission.plan_ids[i]);
    }
    if (progress.has_value()) {
      absl::StatusOr<RobotProgress> p = ProgressFromProto(*progress);
      if (!p.ok()) {
        return absl::Status(
            p.status().code(),
            j >= 0 ? absl::StrFormat("robots[%d].%s", j, p.status().message())
                   : absl::StrCat("the progress recorded for robot ", QuotePrefix(r.robot.id), ": ",
                                  p.status().message()));
      }
      r.progress = *p;
      // Where it is now, for Resume and GetMission's account.
      if (j >= 0 && request.robots(j).has_progress()) {
        progress_->Record(mission.plan_ids[i], *progress);
      }
    }
    if (j >= 0 && request.robots(j).has_pose()) r.pose = PoseFromProto(request.robots(j).pose());
    r.active = !(j >= 0 && request.robots(j).stopped());
    roster->robots.push_back(std::move(r));
    roster->mission_index.push_back(static_cast<int>(i));
    roster->request_index.push_back(j);
    roster->origins.push_back(std::move(origin));
  }
  if (roster->robots.empty()) {
    return absl::FailedPreconditionError(absl::StrCat("every robot of mission ",
                                                      QuotePrefix(mission.mission_id),
                                                      " stopped for good; plan the fleet again"));
  }
  const double tool = roster->base.common.robot.tool_width_m;
  for (auto& [j, robot] : joining) {
    if (robot.robot.tool_width_m != tool) {
      return Invalid(
          j, "joining.robot.tool_width_m",
          absl::StrFormat("%g differs from the mission's %g", robot.robot.tool_width_m, tool));
    }
    MissionRobot r;
    r.robot = std::move(robot);
    r.pose = request.robots(j).has_pose() ? PoseFromProto(request.robots(j).pose())
                                          : *r.robot.robot.start;
    roster->robots.push_back(std::move(r));
    roster->mission_index.push_back(-1);
    roster->request_index.push_back(j);
    roster->origins.push_back(roster->origin);
  }
  return absl::OkStatus();
}

absl::Status MissionHandlers::KeepPlans(const CallInfo& call, const FleetMission& mission,
                                        const Roster& roster, MissionRedivision* redivision,
                                        v1::UpdateMissionResponse* response) {
  MissionRedivisionToProto(*redivision, response);
  response->set_mission_id(mission.mission_id);
  FleetMission updated = mission;
  updated.stopped.resize(updated.robot_ids.size(), false);
  std::map<std::string, size_t> roster_of;
  std::vector<size_t> slot(roster.robots.size());  // roster robot k's index in `updated`
  for (size_t k = 0; k < roster.robots.size(); ++k) {
    const MissionRobot& r = roster.robots[k];
    roster_of[r.robot.id] = k;
    if (roster.mission_index[k] >= 0) {
      slot[k] = static_cast<size_t>(roster.mission_index[k]);
      if (!r.active) updated.stopped[slot[k]] = true;
      continue;
    }
    slot[k] = updated.robot_ids.size();
    updated.robot_ids.push_back(r.robot.id);
    updated.plan_ids.emplace_back();
    updated.stopped.push_back(false);
  }
  const bool stored_map = roster.origin.map_ref_case() == v1::PlanRequest::kMapId;
  for (size_t i = 0; i < redivision->plan.robots.size(); ++i) {
    FleetRobotPlan& rp = redivision->plan.robots[i];
    const size_t k = roster_of.at(redivision->robot_ids[i]);
    FleetRobot robot = roster.robots[k].robot;
    if (!rp.result.plan.path.empty()) {
      const Waypoint& w = rp.result.plan.path.front();
      robot.robot.start = Pose2{w.x, w.y, w.theta};
    }
    auto retained = std::make_shared<RetainedPlan>();
    retained->plan_id = NewPlanId(call.tenant_tag);
    retained->map_id = mission.map_id;
    retained->plan = std::move(rp.result.plan);
    retained->area = std::move(rp.result.area);
    retained->request = roster.base;
    retained->request.common.robot = robot.robot;
    retained->request.battery = robot.battery;
    retained->request.common.stop = StopToken();  // the call's token ends with the call
    v1::PlanResponse* out = response->mutable_robots(static_cast<int>(i))->mutable_plan();
    RetainedPlanFieldsToProto(*retained, out);
    if (stored_map && retained->area != nullptr) {
      // Stored before the mission pushes it onto the robot's session.
      archive_->PersistNow(OriginFor(roster.origins[k], robot), *out);
    }
    updated.plan_ids[slot[k]] = retained->plan_id;
    archive_->Put(std::move(retained));
  }
  archive_->PublishRetainedCount();
  std::vector<std::string> old_plan_ids = mission.plan_ids;
  RETURN_IF_ERROR(missions_->Update(std::move(updated), mission.plan_ids));
  PushPlans(mission, old_plan_ids, *response);
  return absl::OkStatus();
}

void MissionHandlers::PushPlans(const FleetMission& mission,
                                const std::vector<std::string>& old_plan_ids,
                                const v1::UpdateMissionResponse& response) {
  if (drive_ == nullptr) return;
  for (const v1::FleetRobotPlan& robot : response.robots()) {
    size_t i = 0;
    while (i < mission.robot_ids.size() && mission.robot_ids[i] != robot.id()) ++i;
    if (i >= old_plan_ids.size() || robot.plan().plan_id().empty()) continue;  // joined now
    v1::DriveEvent event;
    *event.mutable_replan()->mutable_plan() = robot.plan();
    event.mutable_replan()->mutable_replan()->set_method("mission/redivided");
    event.mutable_mission()->set_mission_id(mission.mission_id);
    event.mutable_mission()->set_cause(v1::MissionNotice::REDIVIDED);
    drive_->PushMissionPlan(old_plan_ids[i], event);
  }
}

}  // namespace covplan
