// PlanFleet: one site planned for a fleet of robots (planner/fleet). The
// call passes the CallGate, is admitted to the solve pool like a Plan
// (SolveAdmission::AdmitPlan: the same bound and deadline-aware queue
// pricing), and on a worker converts the request (api/convert_fleet.h),
// maps the gRPC deadline minus the reply margin onto the fleet's whole
// budget, resolves the stored or inline map as Plan does and runs PlanFleet
// on the service's engine. Each robot's plan is then retained in the
// PlanArchive exactly like a Plan's (its own plan_id, the robot's own
// request, the robot's part of the site as its coverage area) and, on a
// stored map, persisted with the robot's own PlanRequest as its origin, so
// GetPlan, Replan, Resume and Drive accept it. The reply gets a fresh
// mission_id, kept in FleetMissions with the robots' plan ids.
//
//   FleetHandlers fleets(options, store, metrics, &engine, &gate, &admission, &archive,
//                        &missions);
//   return fleets.PlanFleet(context, request, response);
//
// An idle robot (given nothing) gets a retained plan too, but no coverage
// area: Replan and Resume refuse it (FAILED_PRECONDITION), and it is not
// persisted.
//
// Thread-safety: handlers are called concurrently by gRPC; they share only
// thread-safe parts.
#ifndef COVPLAN_SERVER_FLEET_HANDLERS_H_
#define COVPLAN_SERVER_FLEET_HANDLERS_H_

#include "absl/status/status.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "planner/fleet/fleet_request.h"
#include "server/admission.h"
#include "server/call_gate.h"
#include "server/fleet_missions.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/plan_archive.h"
#include "server/service_options.h"

namespace covplan {

class FleetHandlers {
 public:
  // Every pointer outlives this.
  FleetHandlers(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics,
                const PlanningEngine* engine, CallGate* gate, SolveAdmission* admission,
                PlanArchive* archive, FleetMissions* missions)
      : options_(options),
        store_(store),
        metrics_(metrics),
        engine_(engine),
        gate_(gate),
        admission_(admission),
        archive_(archive),
        missions_(missions) {}

  grpc::ServerUnaryReactor* PlanFleet(grpc::CallbackServerContext* context,
                                      const v1::PlanFleetRequest* request,
                                      v1::PlanFleetResponse* response);

 private:
  // The work proper (runs on a worker).
  absl::Status RunPlanFleet(const CallInfo& call, const v1::PlanFleetRequest& request,
                            const StopToken& cancel, v1::PlanFleetResponse* response);
  // Retains (and on a stored map persists) each robot's plan under a fresh
  // plan id, writes the ids, map id and zones into `response`'s robot plans,
  // and records the mission under a fresh mission_id.
  void RetainRobotPlans(const CallInfo& call, const v1::PlanFleetRequest& request,
                        const FleetRequest& fleet, const std::string& map_id, FleetPlan* plan,
                        v1::PlanFleetResponse* response);

  const ServiceOptions& options_;
  MapRepository* const store_;
  ServerMetrics* const metrics_;
  const PlanningEngine* const engine_;
  CallGate* const gate_;
  SolveAdmission* const admission_;
  PlanArchive* const archive_;
  FleetMissions* const missions_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_FLEET_HANDLERS_H_
