// The Drive call (a bidi stream per robot) and the service side of its
// sessions: DriveHandler admits a session (the gate's token and drain
// checks, the bound on open sessions) and is the DriveHost every session
// talks to, adopting plans, replanning through ReplanWork under the solve
// admission, and keeping progress for Resume.
//
//   DriveHandler drive(options, metrics, &gate, &admission, &work, &progress);
//   return drive.Drive(context);  // from the service's override
//   drive.EndAll();               // draining
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_DRIVE_HANDLER_H_
#define COVPLAN_SERVER_DRIVE_HANDLER_H_

#include <functional>
#include <string>
#include <vector>

#include "covplan/v1/covplan.grpc.pb.h"
#include "server/admission.h"
#include "server/call_gate.h"
#include "server/drive_host.h"
#include "server/drive_session.h"
#include "server/fleet_missions.h"
#include "server/live_events.h"
#include "server/metrics.h"
#include "server/progress_log.h"
#include "server/replan_work.h"
#include "server/service_options.h"

namespace covplan {

class DriveHandler final : public DriveHost {
 public:
  // Every pointer outlives this.
  DriveHandler(const ServiceOptions& options, ServerMetrics* metrics, CallGate* gate,
               SolveAdmission* admission, ReplanWork* work, ProgressLog* progress,
               FleetMissions* missions, LiveEvents* live);

  grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent>* Drive(
      grpc::CallbackServerContext* context);
  // Ends every open session with UNAVAILABLE (the server is draining).
  void EndAll() { sessions_.EndAll(); }
  const SessionRegistry& sessions() const { return sessions_; }
  // Pushes a fleet mission's new plan onto the Drive session of the robot
  // that drives `old_plan_id` (if one is open and still drives it). False
  // when no session took it.
  bool PushMissionPlan(const std::string& old_plan_id, const v1::DriveEvent& event);

 private:
  // DriveHost, for the sessions only.
  absl::StatusOr<AdoptedPlan> AdoptPlan(const v1::DriveRequest& first, const StopToken& stop,
                                        const Tenant& tenant) override;
  absl::Status Replan(const std::string& request_id, const Tenant& tenant,
                      const v1::ReplanRequest& request, const StopToken& stop,
                      v1::ReplanResponse* response) override;
  absl::Status SubmitSolve(const Tenant& tenant, std::function<void()> work) override;
  void RecordProgress(const std::string& plan_id, const v1::RobotProgress& progress) override;
  std::optional<v1::RobotProgress> RecordedProgress(const std::string& plan_id) override;
  void ShareObstacles(const std::vector<std::string>& plan_ids,
                      const v1::Obstacles& obstacles) override;
  void PlanAdopted(const std::string& previous, const std::string& plan_id) override;
  bool Watched(const std::string& map_id) override;
  void Live(const v1::LiveEvent& event) override;
  void CountSuperseded() override;
  void UpdateSessionGauge() override;

  const ServiceOptions& options_;
  ServerMetrics* const metrics_;
  CallGate* const gate_;
  SolveAdmission* const admission_;
  ReplanWork* const work_;
  ProgressLog* const progress_;
  FleetMissions* const missions_;
  LiveEvents* const live_;
  SessionRegistry sessions_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_DRIVE_HANDLER_H_
