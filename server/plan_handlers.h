// The plan family of CoveragePlanner calls: Plan and GetPlan.
//
// Plan is a raw method (request and reply as bytes): the request is parsed
// here, and a repeated hit is answered with the bytes already serialised for
// the first one plus this call's timings (server/served_replies.h). A
// repeat whose reply was served before is tried on the gRPC thread first
// (PlanningEngine::Recall); anything else is admitted to the solve pool
// (server/admission.h), planned by the engine within the call's deadline
// minus the reply margin, retained and, on a stored map, persisted
// (server/plan_archive.h). Artifacts a call's deadline cut off are finished
// on a background pool so the next call finds them cached. GetPlan answers
// from the retained plans on the gRPC thread.
//
//   PlanHandlers plans(options, store, metrics, &engine, &gate, &admission, &served,
//                      &archive, &warm_pool, background_stop);
//   return plans.Plan(context, request_bytes, response_bytes);
//
// Thread-safety: handlers are called concurrently by gRPC; they share only
// thread-safe parts.
#ifndef COVPLAN_SERVER_PLAN_HANDLERS_H_
#define COVPLAN_SERVER_PLAN_HANDLERS_H_

#include <cstdint>
#include <memory>
#include <optional>

#include <grpcpp/support/byte_buffer.h>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "server/admission.h"
#include "server/call_gate.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/plan_archive.h"
#include "server/served_replies.h"
#include "server/service_options.h"
#include "server/worker_pool.h"

namespace covplan {

class PlanHandlers {
 public:
  // Every pointer outlives this; `background_stop` is cancelled when the
  // server drains or shuts down.
  PlanHandlers(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics,
               const PlanningEngine* engine, CallGate* gate, SolveAdmission* admission,
               ServedReplies* served, PlanArchive* archive, WorkerPool* warm_pool,
               StopToken background_stop);

  // `request` must parse as a v1::PlanRequest; `response` is a v1::PlanResponse.
  grpc::ServerUnaryReactor* Plan(grpc::CallbackServerContext* context,
                                 const grpc::ByteBuffer* request, grpc::ByteBuffer* response);
  grpc::ServerUnaryReactor* GetPlan(grpc::CallbackServerContext* context,
                                    const v1::GetPlanRequest* request, v1::PlanResponse* response);

 private:
  // What a Plan's worker hands to its reply.
  struct Outcome {
    absl::Status status;
    v1::PlanResponse response;
    std::shared_ptr<const ServedBody> served;
  };

  // The Plan work proper (runs on a worker). A repeated hit sets `*served`
  // and puts only this call's stats into `response`: the reply is then the
  // bytes of `*served` followed by those of `response` (protobuf merges
  // concatenated messages).
  absl::Status RunPlan(const CallInfo& call, const v1::PlanRequest& request,
                       const StopToken& cancel, v1::PlanResponse* response,
                       std::shared_ptr<const ServedBody>* served);
  // Finishes a Plan that ran on a worker.
  void ReplyPlan(CancellableReactor* reactor, const CallInfo& call, std::optional<uint64_t> hit_key,
                 Outcome* outcome, grpc::ByteBuffer* response_bytes);
  // RunPlan's first steps. The engine request of a Plan call started at
  // `start`: its time budget is the request's limit (or the default),
  // capped by the call's deadline minus the reply margin.
  absl::StatusOr<PlanRequest> EngineRequestFor(const CallInfo& call, const v1::PlanRequest& request,
                                               const StopToken& cancel, absl::Time start) const;
  // Where a Plan call's map comes from: a stored map the tenant owns, or the
  // inline one.
  absl::StatusOr<MapSource> PlanMapSource(const CallInfo& call, const v1::PlanRequest& request);
  // A repeated hit answered on the network thread, without a worker: when
  // the engine recalls the remembered plan at once (PlanningEngine::Recall)
  // and its reply was served before, that reply is sent and true returned.
  // Otherwise nothing is sent and the call goes to the worker pool as usual.
  bool ServeRecalledHit(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                        const v1::PlanRequest& request, const StopToken& cancel,
                        grpc::ByteBuffer* response_bytes);
  // The reply already sent for the remembered `entry` to this tenant, if
  // that plan is still retained, with the fresh plan id of this call's
  // mission (an alias of that plan) set in `*response`; else null.
  std::shared_ptr<const ServedBody> ServedReply(const CallInfo& call,
                                                const std::shared_ptr<const RememberedPlan>& entry,
                                                v1::PlanResponse* response);
  // A Plan's solve metrics and, for a call that went through the worker
  // queue (`queued`), the mean solve times the admission prices queued
  // calls with (a hit answered on the gRPC thread would pull them down).
  void RecordPlanSolve(absl::Time start, const PlanStats& stats, bool queued = true);
  // Queues the artifacts of `request` on the background pool (dropped when
  // it is full).
  void WarmInBackground(const MapSource& source, PlanRequest request);

  const ServiceOptions& options_;
  MapRepository* const store_;
  ServerMetrics* const metrics_;
  const PlanningEngine* const engine_;
  CallGate* const gate_;
  SolveAdmission* const admission_;
  ServedReplies* const served_;
  PlanArchive* const archive_;
  WorkerPool* const warm_pool_;
  const StopToken background_stop_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PLAN_HANDLERS_H_
