// UpdateMission and GetMission: a PlanFleet mission (FleetMissions) after
// it started. UpdateMission passes the CallGate and the solve pool's
// admission as PlanFleet does (SolveAdmission::AdmitPlan) and, on a
// worker, builds each robot's MissionRobot: its current plan (PlanArchive),
// its progress on it (the request's, else the one ProgressLog recorded from
// Drive or Replan, else not started) and pose; robots the request does not
// name keep going from their recorded progress, robots marked stopped hand
// their remainder over, joining robots take a share. RedivideMission
// (planner/fleet/mission.h) plans the active robots over what the mission
// has left within the call's budget (BudgetFor, the mission's own time
// limit at most); each new plan is retained under a fresh plan_id (and
// persisted on a stored map) like a PlanFleet robot's, and the mission
// record gets the new plan ids, the stopped flags and the joined robots.
// The new plans are the reply and are pushed onto the robots' open Drive
// sessions (DriveHandler::PushMissionPlan). GetMission reads the record and,
// on a worker like a Replan, the mission's account (AccountMission over each
// robot's current plan and recorded progress).
//
//   MissionHandlers missions(options, store, metrics, &engine, &gate, &admission, &archive,
//                            &progress, &fleet_missions);
//   return missions.UpdateMission(context, request, response);
//
// Thread-safety: handlers are called concurrently by gRPC; they share only
// thread-safe parts. Two concurrent updates of one mission: the later one to
// finish gets ABORTED (FleetMissions::Update).
#ifndef COVPLAN_SERVER_MISSION_HANDLERS_H_
#define COVPLAN_SERVER_MISSION_HANDLERS_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "planner/fleet/mission.h"
#include "server/admission.h"
#include "server/call_gate.h"
#include "server/drive_handler.h"
#include "server/fleet_missions.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/plan_archive.h"
#include "server/progress_log.h"
#include "server/service_options.h"

namespace covplan {

class MissionHandlers {
 public:
  // Every pointer outlives this.
  MissionHandlers(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics,
                  const PlanningEngine* engine, CallGate* gate, SolveAdmission* admission,
                  PlanArchive* archive, ProgressLog* progress, FleetMissions* missions,
                  DriveHandler* drive = nullptr)
      : options_(options),
        store_(store),
        metrics_(metrics),
        engine_(engine),
        gate_(gate),
        admission_(admission),
        archive_(archive),
        progress_(progress),
        missions_(missions),
        drive_(drive) {}

  grpc::ServerUnaryReactor* UpdateMission(grpc::CallbackServerContext* context,
                                          const v1::UpdateMissionRequest* request,
                                          v1::UpdateMissionResponse* response);
  grpc::ServerUnaryReactor* GetMission(grpc::CallbackServerContext* context,
                                       const v1::GetMissionRequest* request,
                                       v1::GetMissionResponse* response);

 private:
  absl::Status RunGetMission(const CallInfo& call, const v1::GetMissionRequest& request,
                             const StopToken& cancel, v1::GetMissionResponse* response);
  // The robots RedivideMission is given, and what UpdateMission keeps of
  // them.
  struct Roster {
    std::vector<MissionRobot> robots;
    std::vector<int> mission_index;        // robots[k]'s index in the mission; -1: joining
    std::vector<int> request_index;        // the request's robots[j] naming it; -1: none
    std::vector<v1::PlanRequest> origins;  // robots[k]'s plan's origin (joining: the first's)
    PlanRequest base;                      // the mission's shared request
    v1::PlanRequest origin;                // the first current plan's origin
  };

  // The work proper (runs on a worker).
  absl::Status RunUpdateMission(const CallInfo& call, const v1::UpdateMissionRequest& request,
                                const StopToken& cancel, v1::UpdateMissionResponse* response);
  // The roster of `mission` with the request's updates; InvalidArgument
  // naming robots[j] of the request.
  absl::Status BuildRoster(const FleetMission& mission, const v1::UpdateMissionRequest& request,
                           const StopToken& stop, Roster* roster);
  // Retains each new plan, fills the reply's plan ids and records the
  // mission's new state.
  absl::Status KeepPlans(const CallInfo& call, const FleetMission& mission, const Roster& roster,
                         MissionRedivision* redivision, v1::UpdateMissionResponse* response);
  // Pushes each robot's new plan onto its open Drive session, if it still
  // drives the plan the mission held (old_plan_ids[i] for robot i).
  void PushPlans(const FleetMission& mission, const std::vector<std::string>& old_plan_ids,
                 const v1::UpdateMissionResponse& response);

  const ServiceOptions& options_;
  MapRepository* const store_;
  ServerMetrics* const metrics_;
  const PlanningEngine* const engine_;
  CallGate* const gate_;
  SolveAdmission* const admission_;
  PlanArchive* const archive_;
  ProgressLog* const progress_;
  FleetMissions* const missions_;
  DriveHandler* const drive_;  // may be null: new plans are pushed onto open Drive sessions
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_MISSION_HANDLERS_H_
