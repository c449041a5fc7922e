// The covplan.v1.CoveragePlanner service on gRPC's callback API: a thin
// composition that owns the service's parts and hands each call to the
// handlers of its family.
//
//   CallGate        token -> tenant, drain, request bounds, finish + record
//   SolveAdmission  the solve pool's bound, queue pricing, in-flight, cut short
//   ServedReplies   repeated identical Plan hits answered from stored bytes
//   PlanArchive     retained plans, their origins, store records, estimator
//   ProgressLog     the robot's progress per plan, for Resume
//   MapHandlers     PutMap, GetMap, ListMaps, DeleteMap
//   PlanHandlers    Plan, GetPlan
//   FleetHandlers   PlanFleet (each robot's plan retained like a Plan's;
//                   FleetMissions keeps mission_id -> robots, plan ids)
//   MissionHandlers UpdateMission (RedivideMission: new plans, new plan ids),
//                   GetMission
//   ReplanHandlers  Replan, Resume (their work: ReplanWork)
//   DriveHandler    Drive, and the DriveHost of its sessions
//
// Handlers never block gRPC threads: solves run on a bounded WorkerPool,
// PutMap's decoding on a small separate one, GetMap / DeleteMap on a third
// (so cheap reads never wait behind decoding), and the reply is sent with
// Finish() from the worker. Beyond worker_threads + max_queue admitted
// solves, Plan answers RESOURCE_EXHAUSTED at once. A Plan's gRPC deadline
// (minus ServiceOptions::deadline_margin) is its anytime budget; a cancelled
// call cancels its StopToken so the work stops. Planning itself is the
// transport-free PlanningEngine (planner/engine); per-map artifacts live in
// one ArtifactLru; artifacts that a call's deadline cut off are finished on a
// background thread, so later calls for the same map find them cached
// instead of failing the same way forever.
//
//   MapStore store = ...; ServerMetrics metrics;
//   CoveragePlannerService service(ServiceOptions{}, store.get(), &metrics);
//   builder.RegisterService(&service);
//   ...
//   service.StartDraining();  // new PutMap/Plan calls get UNAVAILABLE
//   server->Shutdown(deadline);
//   service.Shutdown();       // finishes queued work, joins the pools
//
// Thread-safety: handlers are called concurrently by gRPC; all state is
// internally synchronised.
#ifndef COVPLAN_SERVER_SERVICE_H_
#define COVPLAN_SERVER_SERVICE_H_

#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "planner/replan/replanner.h"
#include "server/admission.h"
#include "server/artifact_lru.h"
#include "server/call_gate.h"
#include "server/drive_handler.h"
#include "server/drive_session.h"
#include "server/fleet_handlers.h"
#include "server/fleet_missions.h"
#include "server/live_events.h"
#include "server/map_handlers.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/mission_handlers.h"
#include "server/plan_archive.h"
#include "server/plan_handlers.h"
#include "server/progress_log.h"
#include "server/replan_handlers.h"
#include "server/replan_work.h"
#include "server/served_replies.h"
#include "server/service_options.h"
#include "server/tenant_quotas.h"
#include "server/tenant_tokens.h"
#include "server/worker_pool.h"

namespace covplan {

class CoveragePlannerService final
    : public v1::CoveragePlanner::WithRawCallbackMethod_Plan<v1::CoveragePlanner::CallbackService> {
 public:
  // `tokens` (optional, outlives the service): every call must carry a
  // bearer token of a tenant, and sees only that tenant's maps and plans.
  // `quotas` (optional, outlives the service): each tenant's quotas; without
  // it every tenant has options.tenant_quota.
  CoveragePlannerService(const ServiceOptions& options, MapRepository* store,
                         ServerMetrics* metrics, const TenantTokens* tokens = nullptr,
                         const TenantQuotas* quotas = nullptr);
  ~CoveragePlannerService() override;

  grpc::ServerUnaryReactor* PutMap(grpc::CallbackServerContext* context,
                                   const v1::PutMapRequest* request,
                                   v1::PutMapResponse* response) override {
    return maps_.PutMap(context, request, response);
  }
  grpc::ServerUnaryReactor* GetMap(grpc::CallbackServerContext* context,
                                   const v1::GetMapRequest* request,
                                   v1::GetMapResponse* response) override {
    return maps_.GetMap(context, request, response);
  }
  grpc::ServerUnaryReactor* ListMaps(grpc::CallbackServerContext* context,
                                     const v1::ListMapsRequest* request,
                                     v1::ListMapsResponse* response) override {
    return maps_.ListMaps(context, request, response);
  }
  grpc::ServerUnaryReactor* DeleteMap(grpc::CallbackServerContext* context,
                                      const v1::DeleteMapRequest* request,
                                      v1::DeleteMapResponse* response) override {
    return maps_.DeleteMap(context, request, response);
  }
  // `request` must parse as a v1::PlanRequest; `response` is a v1::PlanResponse.
  grpc::ServerUnaryReactor* Plan(grpc::CallbackServerContext* context,
                                 const grpc::ByteBuffer* request,
                                 grpc::ByteBuffer* response) override {
    return plans_.Plan(context, request, response);
  }
  grpc::ServerUnaryReactor* GetPlan(grpc::CallbackServerContext* context,
                                    const v1::GetPlanRequest* request,
                                    v1::PlanResponse* response) override {
    return plans_.GetPlan(context, request, response);
  }
  grpc::ServerUnaryReactor* PlanFleet(grpc::CallbackServerContext* context,
                                      const v1::PlanFleetRequest* request,
                                      v1::PlanFleetResponse* response) override {
    return fleets_.PlanFleet(context, request, response);
  }
  grpc::ServerUnaryReactor* UpdateMission(grpc::CallbackServerContext* context,
                                          const v1::UpdateMissionRequest* request,
                                          v1::UpdateMissionResponse* response) override {
    return missions_rpc_.UpdateMission(context, request, response);
  }
  grpc::ServerUnaryReactor* GetMission(grpc::CallbackServerContext* context,
                                       const v1::GetMissionRequest* request,
                                       v1::GetMissionResponse* response) override {
    return missions_rpc_.GetMission(context, request, response);
  }
  grpc::ServerUnaryReactor* Replan(grpc::CallbackServerContext* context,
                                   const v1::ReplanRequest* request,
                                   v1::ReplanResponse* response) override {
    return replans_.Replan(context, request, response);
  }
  grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent>* Drive(
      grpc::CallbackServerContext* context) override {
    return drive_.Drive(context);
  }
  grpc::ServerUnaryReactor* Resume(grpc::CallbackServerContext* context,
                                   const v1::ResumeRequest* request,
                                   v1::ReplanResponse* response) override {
    return replans_.Resume(context, request, response);
  }

  // New calls that start work get UNAVAILABLE, background artifact builds
  // stop, Drive sessions end.
  void StartDraining();
  bool draining() const { return gate_.draining(); }
  // Unary calls between arrival and Finish (health and reflection streams
  // are not counted, so they never hold a drain).
  int active_calls() const { return gate_.active_calls(); }
  // The end of the drain's grace: every running Plan/Replan is stopped and
  // answers with its best plan so far, its termination detail saying the
  // drain cut it short.
  void CutShortInFlight() { admission_.CutShortInFlight(); }
  // Runs what is queued (cancelled calls finish quickly) and joins workers.
  void Shutdown();

  // For tests.
  const ArtifactLru& cache() const { return cache_; }
  const ReplanEstimator& estimator() const { return archive_.estimator(); }
  const SessionRegistry& sessions() const { return drive_.sessions(); }
  // What the Drive sessions do, per map, for the JSON API's event stream.
  LiveEvents* live() { return &live_; }
  const FleetMissions& missions() const { return missions_; }

 private:
  const ServiceOptions options_;
  ArtifactLru cache_;
  const PlannerRegistry registry_;
  const PlanningEngine engine_;
  StopToken background_stop_;                 // cancelled when draining or shutting down
  std::unique_ptr<TenantQuotas> own_quotas_;  // without a caller's quotas
  const TenantQuotas* const quotas_;
  CallGate gate_;
  SolveAdmission admission_;
  ServedReplies served_;
  PlanArchive archive_;
  ProgressLog progress_;
  LiveEvents live_;         // before drive_: the sessions publish to it
  FleetMissions missions_;  // before replan_work_: a mission follows its robots' replans
  ReplanWork replan_work_;
  MapHandlers maps_;
  PlanHandlers plans_;
  FleetHandlers fleets_;
  MissionHandlers missions_rpc_;
  ReplanHandlers replans_;
  DriveHandler drive_;
  // Last: their threads stop before the rest is destroyed.
  WorkerPool io_pool_;    // PutMap (decoding) and plan/estimator writes
  WorkerPool read_pool_;  // GetMap / DeleteMap: never behind decoding
  WorkerPool pool_;       // solves
  WorkerPool warm_pool_;  // artifacts cut off by a caller's deadline
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_SERVICE_H_
