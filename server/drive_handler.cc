#include "server/drive_handler.h"

#include "planner/common/status_macros.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/grpc_status.h"
#include "server/log.h"

namespace covplan {
namespace {

// Ends a Drive call at once (draining, or too many sessions).
class RefusedDrive final : public grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent> {
 public:
  explicit RefusedDrive(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace

DriveHandler::DriveHandler(const ServiceOptions& options, ServerMetrics* metrics, CallGate* gate,
                           SolveAdmission* admission, ReplanWork* work, ProgressLog* progress,
                           FleetMissions* missions, LiveEvents* live)
    : options_(options),
      metrics_(metrics),
      gate_(gate),
      admission_(admission),
      work_(work),
      progress_(progress),
      missions_(missions),
      live_(live),
      sessions_(options.max_sessions, options.session_idle) {}

grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent>* DriveHandler::Drive(
    grpc::CallbackServerContext* context) {
  // A session is not a unary call the drain waits for: StartDraining ends it.
  const CallInfo call = gate_->StartStream(context, "Drive");
  if (!call.auth.ok()) {
    gate_->Record(call, call.auth);
    return new RefusedDrive(ToGrpc(call.auth));
  }
  if (gate_->draining()) {
    metrics_->RecordRequest("Drive", "UNAVAILABLE", 0.0);
    return new RefusedDrive(grpc::Status(grpc::StatusCode::UNAVAILABLE, "server is shutting down"));
  }
  auto* session = new DriveSession(this, context, &sessions_, absl::StrCat("s-", call.request_id),
                                   DriveHost::Tenant{call.tenant_tag, call.tenant});
  if (!sessions_.Add(session)) {
    session->Unref();
    metrics_->RecordRequest("Drive", "RESOURCE_EXHAUSTED", 0.0);
    LogLine("warn", "drive session refused",
            {{"request_id", call.request_id}, {"detail", "too many sessions"}});
    return new RefusedDrive(grpc::Status(
        grpc::StatusCode::RESOURCE_EXHAUSTED,
        absl::StrFormat("too many drive sessions (%d open, --max_sessions); retry later",
                        options_.max_sessions)));
  }
  UpdateSessionGauge();
  LogLine("info", "drive session started",
          {{"request_id", call.request_id}, {"tenant", call.tenant.empty() ? "-" : call.tenant}});
  session->Start();
  return session;
}

absl::StatusOr<DriveHost::AdoptedPlan> DriveHandler::AdoptPlan(const v1::DriveRequest& first,
                                                               const StopToken& stop,
                                                               const Tenant& tenant) {
  return work_->AdoptPlan(first, stop, tenant.tag);
}

absl::Status DriveHandler::Replan(const std::string& request_id, const Tenant& tenant,
                                  const v1::ReplanRequest& request, const StopToken& stop,
                                  v1::ReplanResponse* response) {
  CallInfo call;
  call.method = kDriveReplan.data();
  call.start = absl::Now();
  call.request_id = request_id;
  call.tenant_tag = tenant.tag;
  call.tenant = tenant.name;
  const absl::Status status = work_->RunReplan(call, request, stop, response);
  gate_->Record(call, status,
                status.ok() ? ReplanDetail(*response) : std::string(status.message()));
  return status;
}

absl::Status DriveHandler::SubmitSolve(const Tenant& tenant, std::function<void()> work) {
  if (gate_->draining()) return absl::UnavailableError("server draining: no new replans");
  CallInfo call;
  call.tenant_tag = tenant.tag;
  call.tenant = tenant.name;
  RETURN_IF_ERROR(admission_->Admit(call));
  SolveAdmission::Task task;
  task.solve = std::move(work);
  task.tenant_tag = tenant.tag;
  return admission_->Submit(std::move(task)) ? absl::OkStatus() : admission_->Full();
}

void DriveHandler::RecordProgress(const std::string& plan_id, const v1::RobotProgress& progress) {
  progress_->Record(plan_id, progress);
}

std::optional<v1::RobotProgress> DriveHandler::RecordedProgress(const std::string& plan_id) {
  return progress_->Recorded(plan_id);
}

void DriveHandler::ShareObstacles(const std::vector<std::string>& plan_ids,
                                  const v1::Obstacles& obstacles) {
  if (missions_ == nullptr) return;
  std::optional<std::pair<FleetMission, size_t>> found;
  for (const std::string& plan_id : plan_ids) {
    if ((found = missions_->MissionOfPlan(plan_id)).has_value()) break;
  }
  if (!found.has_value()) return;
  const auto& [mission, from] = *found;
  v1::MissionNotice notice;
  notice.set_mission_id(mission.mission_id);
  notice.set_cause(v1::MissionNotice::SHARED_OBSTACLE);
  notice.set_from_robot(mission.robot_ids[from]);
  for (size_t i = 0; i < mission.plan_ids.size(); ++i) {
    if (i == from || mission.Stopped(i)) continue;
    if (DriveSession* session = sessions_.Find(mission.plan_ids[i])) {
      session->ShareObservation(mission.plan_ids[i], obstacles, notice);
      session->Unref();
    }
  }
}

void DriveHandler::PlanAdopted(const std::string& previous, const std::string& plan_id) {
  if (missions_ != nullptr && !previous.empty()) missions_->ReplacePlan(previous, plan_id);
}

bool DriveHandler::PushMissionPlan(const std::string& old_plan_id, const v1::DriveEvent& event) {
  DriveSession* session = sessions_.Find(old_plan_id);
  if (session == nullptr) return false;
  const bool taken = session->PushMissionPlan(old_plan_id, event);
  session->Unref();
  return taken;
}

bool DriveHandler::Watched(const std::string& map_id) { return live_->Watched(map_id); }

void DriveHandler::Live(const v1::LiveEvent& event) {
  v1::LiveEvent e = event;
  e.set_time_unix_s(absl::ToDoubleSeconds(absl::Now() - absl::UnixEpoch()));
  if (missions_ != nullptr) {
    // A replan's mission may still name the previous plan, or already the new one.
    std::optional<std::pair<FleetMission, size_t>> found = missions_->MissionOfPlan(e.plan_id());
    if (!found.has_value() && e.has_replan()) {
      found = missions_->MissionOfPlan(e.replan().previous_plan_id());
    }
    if (found.has_value()) {
      e.set_mission_id(found->first.mission_id);
      e.set_robot_id(found->first.robot_ids[found->second]);
    }
  }
  live_->Publish(e);
}

void DriveHandler::CountSuperseded() { metrics_->drive_superseded().Increment(); }

void DriveHandler::UpdateSessionGauge() { metrics_->drive_sessions().Set(sessions_.size()); }

}  // namespace covplan
