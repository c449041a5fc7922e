#include "server/plan_handlers.h"

#include <algorithm>
#include <string>
#include <utility>

#include <grpcpp/impl/codegen/proto_utils.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api/convert.h"
#include "planner/common/status_macros.h"
#include "planner/engine/plan_memory.h"
#include "server/log.h"
#include "server/not_found.h"
#include "server/request_limits.h"
#include "server/solve_inputs.h"
#include "server/tenant_tokens.h"

namespace covplan {
PlanHandlers::PlanHandlers(const ServiceOptions& options, MapRepository* store,
                           ServerMetrics* metrics, const PlanningEngine* engine, CallGate* gate,
                           SolveAdmission* admission, ServedReplies* served, PlanArchive* archive,
                           WorkerPool* warm_pool, StopToken background_stop)
    : options_(options),
      store_(store),
      metrics_(metrics),
      engine_(engine),
      gate_(gate),
      admission_(admission),
      served_(served),
      archive_(archive),
      warm_pool_(warm_pool),
      background_stop_(std::move(background_stop)) {}

void PlanHandlers::WarmInBackground(const MapSource& source, PlanRequest request) {
  if (gate_->draining()) return;
  const bool queued = warm_pool_->TrySubmit([this, source, request]() mutable {
    const absl::Time start = absl::Now();
    request.common.stop = background_stop_.WithEarlierDeadline(start + options_.max_request_time);
    const absl::Status built = engine_->Prepare(source, request);
    LogLine(built.ok() ? "info" : "warn", "background artifacts finished",
            {{"map", source.map_id.substr(0, 12)},
             {"tool_m", absl::StrFormat("%g", request.common.robot.tool_width_m)},
             {"ms", absl::StrFormat("%.1f", absl::ToDoubleMilliseconds(absl::Now() - start))},
             {"result", built.ok() ? "cached" : std::string(built.message())}});
  });
  if (!queued) {
    LogLine("warn", "background artifacts dropped: queue full",
            {{"map", source.map_id.substr(0, 12)}});
  }
}

absl::StatusOr<PlanRequest> PlanHandlers::EngineRequestFor(const CallInfo& call,
                                                           const v1::PlanRequest& request,
                                                           const StopToken& cancel,
                                                           absl::Time start) const {
  if (admission_->drain_cut())
    return absl::UnavailableError("server is shutting down; retry on another");
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  ASSIGN_OR_RETURN(PlanRequest plan_request, PlanRequestFromProto(request));
  CommonOptions& options = plan_request.common;
  ASSIGN_OR_RETURN(const CallBudget budget,
                   BudgetFor(options_, call, request.time_limit_s(), cancel, start));
  options.time_limit_s = budget.time_limit_s;
  options.stop = budget.stop;
  return plan_request;
}

absl::StatusOr<MapSource> PlanHandlers::PlanMapSource(const CallInfo& call,
                                                      const v1::PlanRequest& request) {
  return covplan::PlanMapSource(store_, options_.limits, call, request);
}

std::shared_ptr<const ServedBody> PlanHandlers::ServedReply(
    const CallInfo& call, const std::shared_ptr<const RememberedPlan>& entry,
    v1::PlanResponse* response) {
  std::optional<ServedReplies::Served> served = served_->Find(call.tenant_tag, entry);
  if (!served.has_value()) return nullptr;
  // Expired from the retained plans (GetPlan would not find it): planned
  // as a first hit again.
  std::shared_ptr<const RetainedPlan> original = archive_->Get(served->plan_id);
  if (original == nullptr) return nullptr;
  // The same content, a mission of its own.
  const std::string plan_id = NewPlanId(call.tenant_tag);
  archive_->PutAlias(plan_id, original->plan_id);
  response->set_plan_id(plan_id);
  return served->reply;
}

absl::Status PlanHandlers::RunPlan(const CallInfo& call, const v1::PlanRequest& request,
                                   const StopToken& cancel, v1::PlanResponse* response,
                                   std::shared_ptr<const ServedBody>* served) {
  const absl::Time start = absl::Now();
  ASSIGN_OR_RETURN(PlanRequest plan_request, EngineRequestFor(call, request, cancel, start));
  ASSIGN_OR_RETURN(const MapSource source, PlanMapSource(call, request));
  const std::string& map_id = source.map_id;
  absl::StatusOr<EngineResult> result = engine_->Plan(source, plan_request);
  if (!result.ok()) {
    if (IsStop(result.status()) && !cancel.cancelled() && call.deadline != absl::InfiniteFuture()) {
      // Cut off by this call's deadline: finish the artifacts in the
      // background so the next call finds them cached. (A call without a
      // deadline that hit --max_request_s already had that long.)
      WarmInBackground(source, plan_request);
    }
    if (IsStop(result.status()) && admission_->drain_cut()) {
      return absl::UnavailableError(
          "server shut down before a first plan was found; retry on another");
    }
    return IsStop(result.status())
               ? StoppedStatus(result.status(), cancel, call, start, options_.max_request_time)
               : result.status();
  }
  if (result->answered_by != nullptr) {
    if (std::shared_ptr<const ServedBody> reply =
            ServedReply(call, result->answered_by, response)) {
      *served = std::move(reply);
      response->mutable_stats()->set_planning_ms(result->plan.stats.planning_ms);
      response->mutable_stats()->set_decomposition_cached(result->plan.stats.decomposition_cached);
      RecordPlanSolve(start, result->plan.stats);
      return absl::OkStatus();
    }
  }
  auto retained = std::make_shared<RetainedPlan>();
  retained->plan_id = NewPlanId(call.tenant_tag);
  retained->map_id = map_id;
  retained->plan = std::move(result->plan);
  retained->area = std::move(result->area);
  retained->request = std::move(plan_request);
  retained->request.common.stop = StopToken();  // the call's token ends with the call
  RetainedPlanToProto(*retained, response);
  if (admission_->drain_cut() && response->termination().limit() == v1::LIMIT_CANCELLED) {
    response->mutable_termination()->set_detail(absl::StrCat(
        "cut short by the server's drain (shutting down); ", response->termination().detail()));
  }
  if (request.map_ref_case() == v1::PlanRequest::kMapId) archive_->Persist(request, *response);
  RecordPlanSolve(start, retained->plan.stats);
  archive_->Put(std::move(retained));
  archive_->PublishRetainedCount();
  // Only plans the store keeps too: a repeated hit is an alias of this plan
  // (its stored record names this one), so this plan must stay resolvable
  // after a restart (plans of inline maps are not stored).
  if (result->answered_by != nullptr && request.map_ref_case() == v1::PlanRequest::kMapId) {
    served_->Remember(call.tenant_tag, *result, *response);
  }
  return absl::OkStatus();
}

bool PlanHandlers::ServeRecalledHit(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                                    const v1::PlanRequest& request, const StopToken& cancel,
                                    grpc::ByteBuffer* response_bytes) {
  const absl::Time start = absl::Now();
  absl::StatusOr<PlanRequest> plan_request = EngineRequestFor(call, request, cancel, start);
  if (!plan_request.ok()) return false;
  absl::StatusOr<MapSource> source = PlanMapSource(call, request);
  if (!source.ok()) return false;
  absl::StatusOr<std::optional<Recalled>> recalled = engine_->Recall(*source, *plan_request);
  if (!recalled.ok() || !recalled->has_value()) return false;
  // As RunPlan answers a repeated hit: the served bytes, then this call's
  // plan id and stats.
  v1::PlanResponse response;
  std::shared_ptr<const ServedBody> served = ServedReply(call, (*recalled)->entry, &response);
  if (served == nullptr) return false;
  response.mutable_stats()->set_planning_ms((*recalled)->lookup_ms);
  response.mutable_stats()->set_decomposition_cached(true);
  PlanStats solve;  // what the solve metrics read
  solve.plan_source = PlanOrigin::kCacheHit;
  solve.tour_cut_short = (*recalled)->entry->plan.stats.tour_cut_short;
  RecordPlanSolve(start, solve, /*queued=*/false);
  metrics_->hits_without_worker().Increment();
  const std::string detail =
      absl::StrCat("plan=", response.plan_id(), " ", served->detail, " cached=1");
  gate_->Finish(reactor, call, SerializePlanReply(response, std::move(served), response_bytes),
                detail);
  return true;
}

void PlanHandlers::RecordPlanSolve(absl::Time start, const PlanStats& stats, bool queued) {
  const int64_t solve_us = absl::ToInt64Microseconds(absl::Now() - start);
  metrics_->RecordSolve(solve_us * 1e-6, stats.tour_cut_short);
  metrics_->RecordPlanSource(PlanOriginName(stats.plan_source));
  if (!queued) return;
  admission_->RecordPlanTime(absl::Microseconds(solve_us),
                             stats.plan_source == PlanOrigin::kCacheHit);
}

grpc::ServerUnaryReactor* PlanHandlers::Plan(grpc::CallbackServerContext* context,
                                             const grpc::ByteBuffer* request_bytes,
                                             grpc::ByteBuffer* response_bytes) {
  auto* reactor = new CancellableReactor();
  const CallInfo call = gate_->Start(context, "Plan");
  // Parsed first, as gRPC parses the other methods' requests before their
  // handlers (and their auth checks) run.
  auto request = std::make_shared<v1::PlanRequest>();
  {
    grpc::ByteBuffer bytes = *request_bytes;  // shares the slices; Deserialize consumes it
    if (!grpc::SerializationTraits<v1::PlanRequest>::Deserialize(&bytes, request.get()).ok()) {
      gate_->Finish(reactor, call,
                    absl::InvalidArgumentError(absl::StrCat(
                        "request is not a valid ", v1::PlanRequest::descriptor()->full_name(),
                        " protobuf message")));
      return reactor;
    }
  }
  if (!gate_->Admit(reactor, call, *request, WhileDraining::kRefuse)) return reactor;
  // The request's bytes, tagged with the tenant: a repeat of a request that
  // was answered from memory is expected to be answered from memory again.
  const std::optional<uint64_t> hit_key =
      ServedReplies::HitKey(call.tenant_tag, *request, *request_bytes);
  const bool likely_hit = hit_key.has_value() && served_->IsHitRequest(*hit_key);
  // A repeat whose reply was served before takes microseconds: answered
  // here, it neither waits behind searches nor costs a thread hand-off.
  if (likely_hit && ServeRecalledHit(reactor, call, *request, reactor->cancel(), response_bytes)) {
    return reactor;
  }
  if (absl::Status admitted = admission_->AdmitPlan(call, likely_hit); !admitted.ok()) {
    gate_->Finish(reactor, call, admitted);
    return reactor;
  }
  auto outcome = std::make_shared<Outcome>();
  SolveAdmission::Task task;
  task.solve = [this, reactor, call, request, outcome] {
    admission_->UpdateQueueGauge();
    outcome->status =
        RunPlan(call, *request, reactor->cancel(), &outcome->response, &outcome->served);
  };
  task.reply = [this, reactor, call, hit_key, outcome, response_bytes] {
    ReplyPlan(reactor, call, hit_key, outcome.get(), response_bytes);
  };
  task.cut_short = reactor->cancel();
  task.likely_hit = likely_hit;
  task.tenant_tag = call.tenant_tag;
  const bool queued = admission_->Submit(std::move(task));
  admission_->UpdateQueueGauge();
  if (!queued) gate_->Finish(reactor, call, admission_->Full());
  return reactor;
}

void PlanHandlers::ReplyPlan(CancellableReactor* reactor, const CallInfo& call,
                             std::optional<uint64_t> hit_key, Outcome* outcome,
                             grpc::ByteBuffer* response_bytes) {
  absl::Status status = outcome->status;
  const v1::PlanResponse& response = outcome->response;
  if (status.ok() && hit_key.has_value()) {
    // Remembered while it is answered from memory; forgotten once it is
    // not (the plan or its map was evicted or deleted).
    served_->NoteHitRequest(
        *hit_key,
        outcome->served != nullptr || response.stats().plan_source() == v1::PLAN_SOURCE_CACHE_HIT);
  }
  std::string detail;
  if (status.ok()) {
    detail = absl::StrCat(outcome->served != nullptr ? absl::StrCat("plan=", response.plan_id(),
                                                                    " ", outcome->served->detail)
                                                     : PlanDetail(response),
                          " cached=", response.stats().decomposition_cached() ? 1 : 0);
    status = SerializePlanReply(response, std::move(outcome->served), response_bytes);
  }
  gate_->Finish(reactor, call, status, detail);
  admission_->TrimMemoryIfIdle(absl::Now() - call.start);
}

grpc::ServerUnaryReactor* PlanHandlers::GetPlan(grpc::CallbackServerContext* context,
                                                const v1::GetPlanRequest* request,
                                                v1::PlanResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  CallInfo call;
  if (!gate_->Open(context, "GetPlan", reactor, *request, WhileDraining::kServe, &call)) {
    return reactor;
  }
  std::shared_ptr<const RetainedPlan> plan =
      OwnsPlan(call.tenant_tag, request->plan_id()) ? archive_->Get(request->plan_id()) : nullptr;
  archive_->PublishRetainedCount();
  if (plan == nullptr) {
    gate_->Finish(reactor, call, PlanNotFound(request->plan_id()));
    return reactor;
  }
  RetainedPlanToProto(*plan, response);  // in memory, no blocking
  gate_->Finish(reactor, call, absl::OkStatus(), QuotePrefix(request->plan_id()));
  return reactor;
}

}  // namespace covplan
