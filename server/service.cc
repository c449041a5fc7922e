#include "server/service.h"
#include "planner/assembly/builtin_planners.h"

#include <malloc.h>
#include <sys/random.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/slice.h>

#include "absl/hash/hash.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/engine/plan_memory.h"
#include "planner/grid/grid.h"
#include "server/log.h"
#include "server/request_limits.h"

namespace covplan {
namespace {

constexpr char kEstimatorFile[] = "replan_estimator.txt";

EngineLimits EngineLimitsWithMemory(const ServiceOptions& options) {
  EngineLimits limits = options.limits;
  limits.plan_memory = options.plan_memory;
  return limits;
}

// The answers for an id that does not exist, also given for another
// tenant's id, so a caller cannot tell the two apart.
absl::Status MapNotFound(const std::string& map_id) {
  return absl::NotFoundError(
      absl::StrCat("unknown map_id ", map_id.substr(0, 80), "; PutMap it first"));
}
absl::Status PlanNotFound(const std::string& plan_id) {
  return absl::NotFoundError(
      absl::StrCat("unknown or expired plan_id '", plan_id.substr(0, 80), "'"));
}

// Status messages are bounded (they travel in trailing metadata, whose size
// the client limits; an over-long one would turn the real error into
// RESOURCE_EXHAUSTED on the client).
std::string BoundedMessage(absl::string_view message) {
  if (message.size() <= kMaxMessageBytes) return std::string(message);
  return absl::StrCat(message.substr(0, kMaxMessageBytes - 24), "...(truncated)");
}

grpc::Status ToGrpc(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  return grpc::Status(static_cast<grpc::StatusCode>(status.code()),
                      BoundedMessage(status.message()));
}

// A Plan stopped by its deadline before a first plan is overload
// (RESOURCE_EXHAUSTED), not a too-short deadline, when it spent more than this
// share of its deadline in the queue.
constexpr double kQueueShareForOverload = 0.1;

// Calls that worked this long are followed by a malloc_trim.
constexpr absl::Duration kTrimAfterWork = absl::Milliseconds(50);

// Page sizes of ListMaps (AIP-158).
constexpr int kDefaultPageSize = 100;
constexpr int kMaxPageSize = 1000;

std::string CodeName(const absl::Status& status) { return absl::StatusCodeToString(status.code()); }

absl::Time DeadlineOf(const grpc::CallbackServerContext& context) {
  const auto deadline = context.deadline();
  // gRPC reports "no deadline" as a far-future time point.
  if (deadline >= std::chrono::system_clock::now() + std::chrono::hours(24 * 365)) {
    return absl::InfiniteFuture();
  }
  return absl::FromChrono(deadline);
}

bool IsStop(const absl::Status& status) {
  return absl::IsDeadlineExceeded(status) || absl::IsCancelled(status);
}

// The status for work that stopped early: the client's cancellation wins,
// otherwise the deadline was too short for even a first plan.
absl::Status StoppedStatus(const absl::Status& status, const StopToken& cancel,
                           const CallInfo& call, absl::Time started,
                           absl::Duration max_request_time) {
  if (cancel.cancelled())
    return absl::CancelledError("call cancelled (by the client, or by the server's drain)");
  // A call that spent a real share of its deadline waiting for a worker was
  // refused by overload, not by its own deadline: say so with the code a
  // client retries on (elsewhere).
  if (call.deadline != absl::InfiniteFuture() && absl::IsDeadlineExceeded(status)) {
    const absl::Duration waited = started - call.start;
    if (waited > kQueueShareForOverload * (call.deadline - call.start)) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "server busy: the call waited %d ms of its %d ms deadline for a worker and had no time "
          "left for a first plan; retry later or elsewhere",
          absl::ToInt64Milliseconds(waited),
          absl::ToInt64Milliseconds(call.deadline - call.start)));
    }
  }
  if (call.deadline == absl::InfiniteFuture() && absl::IsDeadlineExceeded(status)) {
    return absl::DeadlineExceededError(
        absl::StrFormat("no plan within the server's limit of %g s per call without a deadline "
                        "(--max_request_s) (%s); use a wider tool or a smaller map",
                        absl::ToDoubleSeconds(max_request_time), status.message()));
  }
  if (absl::IsDeadlineExceeded(status) || call.deadline != absl::InfiniteFuture()) {
    return absl::DeadlineExceededError(
        absl::StrFormat("deadline of %d ms too short for a first plan (%s)",
                        absl::ToInt64Milliseconds(call.deadline - call.start), status.message()));
  }
  return status;
}

// A Plan reply's log summary, without the per-call decomposition_cached.
std::string PlanDetail(const v1::PlanResponse& response) {
  return absl::StrFormat("plan=%s planner=%s ranks=%d termination=%s/%s source=%s",
                         response.plan_id(), response.planner(), response.stats().num_ranks(),
                         v1::TerminationReason_Name(response.termination().reason()),
                         v1::TerminationLimit_Name(response.termination().limit()),
                         v1::PlanSource_Name(response.stats().plan_source()));
}

// Lets one worker call and the reactor share the cancellation token; the
// reactor deletes itself when gRPC is done with the call.
class PlanReactor final : public grpc::ServerUnaryReactor {
 public:
  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }
  const StopToken& cancel() const { return cancel_; }

 private:
  StopToken cancel_;
};

}  // namespace

std::shared_ptr<const CoveragePlannerService::ServedBody> ServedBodyFor(
    const v1::PlanResponse& reply) {
  // The per-call fields are cleared: proto3 does not write a zero, so a
  // zero in the call's appended stats would not override a stored value.
  v1::PlanResponse stored = reply;
  stored.mutable_stats()->clear_planning_ms();
  stored.mutable_stats()->clear_decomposition_cached();
  auto body = std::make_shared<CoveragePlannerService::ServedBody>();
  if (!stored.SerializeToString(&body->bytes)) return nullptr;
  body->detail = PlanDetail(stored);
  return body;
}

absl::Status SerializePlanReply(const v1::PlanResponse& response,
                                std::shared_ptr<const CoveragePlannerService::ServedBody> served,
                                grpc::ByteBuffer* out) {
  grpc::ByteBuffer tail;
  bool own = false;
  if (!grpc::SerializationTraits<v1::PlanResponse>::Serialize(response, &tail, &own).ok()) {
    return absl::InternalError("could not serialise the plan reply");
  }
  if (served == nullptr) {
    out->Swap(&tail);
    return absl::OkStatus();
  }
  std::vector<grpc::Slice> slices;
  if (!tail.Dump(&slices).ok()) return absl::InternalError("could not serialise the plan reply");
  using Body = std::shared_ptr<const CoveragePlannerService::ServedBody>;
  const std::string& bytes = served->bytes;
  auto* keep = new Body(std::move(served));  // released with the slice
  slices.insert(slices.begin(), grpc::Slice(
                                    const_cast<char*>(bytes.data()), bytes.size(),
                                    [](void* p) { delete static_cast<Body*>(p); }, keep));
  grpc::ByteBuffer whole(slices.data(), slices.size());
  out->Swap(&whole);
  return absl::OkStatus();
}

absl::Status ServiceOptions::Validate() const {
  if (absl::Status s = limits.Validate(); !s.ok()) return s;
  if (worker_threads < 1) return absl::InvalidArgumentError("worker_threads must be >= 1");
  if (max_queue < 0) return absl::InvalidArgumentError("max_queue must be >= 0");
  if (!(default_budget_s > 0)) return absl::InvalidArgumentError("default_budget_s must be > 0");
  if (deadline_margin < absl::ZeroDuration()) {
    return absl::InvalidArgumentError("deadline_margin must be >= 0");
  }
  if (max_request_time <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("max_request_time must be > 0");
  }
  if (max_sessions < 0) return absl::InvalidArgumentError("max_sessions must be >= 0");
  if (session_idle <= absl::ZeroDuration())
    return absl::InvalidArgumentError("session_idle must be > 0");
  return absl::OkStatus();
}

CoveragePlannerService::CoveragePlannerService(const ServiceOptions& options, MapRepository* store,
                                               ServerMetrics* metrics, const TenantTokens* tokens)
    : options_(options),
      store_(store),
      tokens_(tokens),
      metrics_(metrics),
      cache_(options.cache_budget_bytes, metrics),
      registry_(BuiltinPlanners()),
      engine_(&registry_, &cache_, EngineLimitsWithMemory(options)),
      plans_(options.plan_ttl, options.max_retained_plans),
      sessions_(options.max_sessions, options.session_idle),
      id_salt_(std::random_device{}()),
      io_pool_(/*threads=*/2, /*max_queue=*/64),
      read_pool_(/*threads=*/1, /*max_queue=*/256),
      // Admission is bounded by TryAdmitSolve; the pool's own bound is slack
      // for solves that have released their slot but not yet returned.
      pool_(options.worker_threads, 2 * (options.worker_threads + options.max_queue)),
      warm_pool_(/*threads=*/1, /*max_queue=*/4) {
  metrics_->worker_threads().Set(options.worker_threads);
  metrics_->queue_capacity().Set(options.max_queue);
  metrics_->cache_budget_bytes().Set(static_cast<double>(options.cache_budget_bytes));
  metrics_->maps_stored().Set(static_cast<double>(store_->size()));
  // The replan estimator learned by earlier runs of this server.
  store_->TrimPlans(options_.max_stored_plans);
  if (absl::StatusOr<std::string> saved = store_->GetState(kEstimatorFile); saved.ok()) {
    const absl::Status parsed = estimator_.Parse(*saved);
    LogLine(parsed.ok() ? "info" : "warn", "replan estimator loaded",
            {{"samples", absl::StrCat(estimator_.num_samples())},
             {"detail", parsed.ok() ? "" : std::string(parsed.message())}});
  }
  metrics_->SetReplanEstimator(estimator_.coefficients().a, estimator_.coefficients().b,
                               estimator_.coefficients().c, estimator_.num_samples());
}

CoveragePlannerService::~CoveragePlannerService() { Shutdown(); }

void CoveragePlannerService::Shutdown() {
  background_stop_.Cancel();
  warm_pool_.Shutdown();
  pool_.Shutdown();
  io_pool_.Shutdown();
  read_pool_.Shutdown();
}

CallInfo CoveragePlannerService::StartCall(grpc::CallbackServerContext* context,
                                           const char* method) {
  CallInfo call;
  call.method = method;
  call.start = absl::Now();
  call.deadline = DeadlineOf(*context);
  active_calls_.fetch_add(1);
  const auto& metadata = context->client_metadata();
  if (auto it = metadata.find("x-request-id"); it != metadata.end() && it->second.size() <= 64) {
    call.request_id.assign(it->second.data(), it->second.size());
    for (char& c : call.request_id) {
      if (c <= ' ' || c > '~' || c == '"') c = '_';
    }
  }
  if (call.request_id.empty()) {
    call.request_id = absl::StrFormat("%08x-%06x", static_cast<uint32_t>(id_salt_),
                                      next_id_.fetch_add(1, std::memory_order_relaxed));
  }
  context->AddInitialMetadata("x-request-id", call.request_id);
  if (tokens_ != nullptr) {
    auto it = metadata.find("authorization");
    const absl::string_view authorization =
        it == metadata.end() ? absl::string_view()
                             : absl::string_view(it->second.data(), it->second.size());
    absl::StatusOr<std::string> tenant = tokens_->Authenticate(authorization);
    if (tenant.ok()) {
      call.tenant_tag = TenantTag(*tenant);
    } else {
      call.auth = tenant.status();
    }
  }
  return call;
}

void CoveragePlannerService::FinishCall(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                                        const absl::Status& status, const std::string& detail) {
  RecordCall(call, status, detail);
  reactor->Finish(ToGrpc(status));
  active_calls_.fetch_sub(1);
}

void CoveragePlannerService::RecordCall(const CallInfo& call, const absl::Status& status,
                                        const std::string& detail) {
  const absl::Time now = absl::Now();
  const double seconds = absl::ToDoubleSeconds(now - call.start);
  metrics_->RecordRequest(call.method, CodeName(status), seconds);
  const bool late = now > call.deadline;
  LogLine(status.ok() ? "info" : "warn", "request finished",
          {{"req", call.request_id},
           {"method", call.method},
           {"code", CodeName(status)},
           {"ms", absl::StrFormat("%.1f", seconds * 1e3)},
           {"late", late ? "true" : "false"},
           {"detail", BoundedMessage(status.ok() ? detail : std::string(status.message()))}});
}

void CoveragePlannerService::MaybeTrimMemory(absl::Duration work) {
  // Large solves and decodes leave freed pages in glibc's arenas; give them
  // back (off the reply's path, when idle, at most every 100 ms) so resident memory
  // follows the budgets instead of the high-water mark.
  if (work < kTrimAfterWork) return;
  // malloc_trim locks every arena in turn: only when no solve runs or waits,
  // so it never stalls a call that is racing its deadline.
  if (in_flight_.load() != 0 || pool_.queued() != 0) return;
  const int64_t now_ms = absl::ToUnixMillis(absl::Now());
  int64_t last = last_trim_ms_.load();
  if (now_ms - last < 100 || !last_trim_ms_.compare_exchange_strong(last, now_ms)) return;
  ::malloc_trim(0);
}

uint64_t CoveragePlannerService::TrackSolve(const StopToken& token) {
  absl::MutexLock lock(&solves_mu_);
  const uint64_t id = next_solve_++;
  solves_.emplace(id, token);
  if (drain_cut_.load()) token.Cancel();
  return id;
}

void CoveragePlannerService::UntrackSolve(uint64_t id) {
  absl::MutexLock lock(&solves_mu_);
  solves_.erase(id);
}

void CoveragePlannerService::CutShortInFlight() {
  absl::MutexLock lock(&solves_mu_);
  drain_cut_.store(true);
  for (const auto& [id, token] : solves_) token.Cancel();
  if (!solves_.empty()) {
    LogLine("warn", "drain grace over: cutting running solves short",
            {{"solves", absl::StrCat(solves_.size())}});
  }
}

bool CoveragePlannerService::SubmitIo(std::function<void()> work) {
  return io_pool_.TrySubmit(std::move(work));
}

absl::Status CoveragePlannerService::QueuedTooLong(const CallInfo& call,
                                                   const StopToken& cancel) const {
  // gRPC also cancels a call whose deadline passed: say which it was.
  const absl::Time now = absl::Now();
  if (now >= call.deadline) {
    return absl::DeadlineExceededError(
        absl::StrFormat("deadline passed while the call waited %d ms for a worker; not started",
                        absl::ToInt64Milliseconds(now - call.start)));
  }
  if (cancel.cancelled())
    return absl::CancelledError("call cancelled while it waited for a worker; not started");
  return absl::OkStatus();
}

bool CoveragePlannerService::TryAdmitSolve() {
  const int capacity = options_.worker_threads + options_.max_queue;
  int admitted = admitted_.load();
  while (admitted < capacity) {
    if (admitted_.compare_exchange_weak(admitted, admitted + 1)) return true;
  }
  return false;
}

void CoveragePlannerService::ReleaseSolve() { admitted_.fetch_sub(1); }

void CoveragePlannerService::UpdateQueueGauges() { metrics_->queue_depth().Set(pool_.queued()); }

std::string CoveragePlannerService::NewPlanId(const std::string& tenant_tag) {
  // 128 bits from the kernel's CSPRNG: a plan id cannot be guessed from
  // another one.
  unsigned char bytes[16];
  size_t got = 0;
  while (got < sizeof(bytes)) {
    const ssize_t n = ::getrandom(bytes + got, sizeof(bytes) - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      // getrandom cannot fail on Linux >= 3.17 once the pool is seeded; if it
      // ever does, refuse to hand out a guessable id.
      LogLine("error", "getrandom failed", {{"errno", absl::StrCat(errno)}});
      std::abort();
    }
    got += static_cast<size_t>(n);
  }
  std::string id = "p-";
  for (unsigned char b : bytes) absl::StrAppendFormat(&id, "%02x", b);
  return id + PlanIdSuffix(tenant_tag);
}

// ---------------------------------------------------------------- maps

absl::Status CoveragePlannerService::RunPutMap(const v1::PutMapRequest& request,
                                               const std::string& tenant_tag,
                                               v1::PutMapResponse* response) {
  ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(request.map(), options_.limits));
  RETURN_IF_ERROR(CheckSiteGeometry(site));
  // Per tenant: the same content stored by two tenants is two maps.
  const std::string map_id = ScopedMapId(ComputeMapId(request.map()), tenant_tag);
  v1::MapInfo info = MapInfoFor(site, map_id);
  info.set_name(request.name());
  ASSIGN_OR_RETURN(bool created, store_->Put(info, request.map()));
  // A rewritten (repaired) map must not be planned from artifacts of the
  // damaged copy; the content is the same, but be safe and cheap: drop them.
  if (created) cache_.EraseWithPrefix(map_id + "/");
  if (!created) {
    ASSIGN_OR_RETURN(v1::GetMapResponse stored, store_->Get(map_id));
    info = stored.info();
  }
  response->set_map_id(map_id);
  response->set_created(created);
  *response->mutable_info() = info;
  metrics_->maps_stored().Set(static_cast<double>(store_->size()));
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* CoveragePlannerService::PutMap(grpc::CallbackServerContext* context,
                                                         const v1::PutMapRequest* request,
                                                         v1::PutMapResponse* response) {
  auto* reactor = new PlanReactor();
  CallInfo call = StartCall(context, "PutMap");
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (draining()) {
    FinishCall(reactor, call, absl::UnavailableError("server is shutting down"));
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  if (!SubmitIo([this, reactor, call, request, response] {
        // Work whose caller gave up while it was queued is dropped unstarted.
        absl::Status status = QueuedTooLong(call, reactor->cancel());
        if (status.ok()) status = RunPutMap(*request, call.tenant_tag, response);
        FinishCall(reactor, call, status, response->map_id());
        MaybeTrimMemory(absl::Now() - call.start);
      })) {
    FinishCall(reactor, call, absl::ResourceExhaustedError("server busy: work queue is full"));
  }
  return reactor;
}

grpc::ServerUnaryReactor* CoveragePlannerService::GetMap(grpc::CallbackServerContext* context,
                                                         const v1::GetMapRequest* request,
                                                         v1::GetMapResponse* response) {
  auto* reactor = new PlanReactor();
  CallInfo call = StartCall(context, "GetMap");
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  // On the read pool: never behind PutMap's decoding.
  if (!read_pool_.TrySubmit([this, reactor, call, request, response] {
        if (absl::Status s = QueuedTooLong(call, reactor->cancel()); !s.ok()) {
          FinishCall(reactor, call, s);
          return;
        }
        // Another tenant's map answers as a missing one.
        absl::StatusOr<v1::GetMapResponse> stored = MapNotFound(request->map_id());
        if (OwnsMap(call.tenant_tag, request->map_id()) || !ValidateMapId(request->map_id()).ok()) {
          stored = store_->Get(request->map_id());  // a malformed id: INVALID_ARGUMENT for all
        }
        if (absl::IsNotFound(stored.status())) stored = MapNotFound(request->map_id());
        if (absl::IsDataLoss(stored.status())) cache_.EraseWithPrefix(request->map_id() + "/");
        if (stored.ok()) {
          *response->mutable_info() = stored->info();
          if (request->include_content())
            *response->mutable_map() = std::move(*stored->mutable_map());
        }
        FinishCall(reactor, call, stored.status(), QuotePrefix(request->map_id()));
      })) {
    FinishCall(reactor, call, absl::ResourceExhaustedError("server busy: work queue is full"));
  }
  return reactor;
}

grpc::ServerUnaryReactor* CoveragePlannerService::ListMaps(grpc::CallbackServerContext* context,
                                                           const v1::ListMapsRequest* request,
                                                           v1::ListMapsResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  CallInfo call = StartCall(context, "ListMaps");
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  if (request->page_size() < 0) {
    FinishCall(reactor, call,
               absl::InvalidArgumentError(
                   absl::StrCat("page_size must be >= 0 (got ", request->page_size(), ")")));
    return reactor;
  }
  // The token is the last map_id of the previous page (ids are sorted).
  const std::string& token = request->page_token();
  if (!token.empty() && !ValidateMapId(token).ok()) {
    FinishCall(reactor, call,
               absl::InvalidArgumentError(absl::StrCat("page_token '", QuotePrefix(token),
                                                       "' is not a next_page_token of ListMaps")));
    return reactor;
  }
  const int page_size =
      request->page_size() == 0 ? kDefaultPageSize : std::min(request->page_size(), kMaxPageSize);
  std::vector<std::string> corrupted;  // in-memory index only: cheap
  bool more = false;
  absl::StatusOr<std::vector<v1::MapInfo>> page =
      store_->ListPage(token, page_size, &more, token.empty() ? &corrupted : nullptr);
  if (!page.ok()) {
    FinishCall(reactor, call, page.status());
    return reactor;
  }
  if (!call.tenant_tag.empty()) {
    // Only the caller's maps: keep reading pages until this one is full.
    const auto foreign = [&](const std::string& id) { return !OwnsMap(call.tenant_tag, id); };
    corrupted.erase(std::remove_if(corrupted.begin(), corrupted.end(), foreign), corrupted.end());
    std::vector<v1::MapInfo> mine;
    while (true) {
      const std::string last = page->empty() ? "" : page->back().map_id();
      for (v1::MapInfo& info : *page) {
        if (!foreign(info.map_id())) mine.push_back(std::move(info));
      }
      if (!more || static_cast<int>(mine.size()) >= page_size || last.empty()) break;
      page = store_->ListPage(last, page_size, &more, nullptr);
      if (!page.ok()) {
        FinishCall(reactor, call, page.status());
        return reactor;
      }
    }
    if (static_cast<int>(mine.size()) > page_size) {
      mine.resize(page_size);
      more = true;
    }
    *page = std::move(mine);
  }
  for (v1::MapInfo& info : *page) {
    // Names are bounded at PutMap; older stores may hold longer ones.
    if (info.name().size() > kMapNameLimit) info.mutable_name()->resize(kMapNameLimit);
    *response->add_maps() = std::move(info);
  }
  if (corrupted.size() > static_cast<size_t>(kMaxPageSize)) corrupted.resize(kMaxPageSize);
  for (std::string& id : corrupted) response->add_corrupted(std::move(id));
  if (more && response->maps_size() > 0) {
    response->set_next_page_token(response->maps(response->maps_size() - 1).map_id());
  }
  FinishCall(reactor, call, absl::OkStatus());
  return reactor;
}

grpc::ServerUnaryReactor* CoveragePlannerService::DeleteMap(grpc::CallbackServerContext* context,
                                                            const v1::DeleteMapRequest* request,
                                                            v1::DeleteMapResponse* response) {
  auto* reactor = new PlanReactor();
  CallInfo call = StartCall(context, "DeleteMap");
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  if (!read_pool_.TrySubmit([this, reactor, call, request, response] {
        if (absl::Status s = QueuedTooLong(call, reactor->cancel()); !s.ok()) {
          FinishCall(reactor, call, s);
          return;
        }
        // Another tenant's map answers as a missing one: nothing deleted.
        absl::StatusOr<bool> deleted = false;
        if (OwnsMap(call.tenant_tag, request->map_id()) || !ValidateMapId(request->map_id()).ok()) {
          deleted = store_->Delete(request->map_id());
        }
        if (deleted.ok()) {
          response->set_deleted(*deleted);
          cache_.EraseWithPrefix(request->map_id() + "/");
          metrics_->maps_stored().Set(static_cast<double>(store_->size()));
        }
        FinishCall(reactor, call, deleted.status(), QuotePrefix(request->map_id()));
      })) {
    FinishCall(reactor, call, absl::ResourceExhaustedError("server busy: work queue is full"));
  }
  return reactor;
}

// ---------------------------------------------------------------- plans

MapSource CoveragePlannerService::SourceFor(const std::string& map_id,
                                            std::shared_ptr<const v1::Map> inline_map) {
  MapSource source;
  source.map_id = map_id;
  source.load = [this, map_id, inline_map]() -> absl::StatusOr<SiteMap> {
    v1::GetMapResponse stored;
    if (inline_map == nullptr) {
      absl::StatusOr<v1::GetMapResponse> got = store_->Get(map_id);
      if (absl::IsNotFound(got.status())) return MapNotFound(map_id);
      if (!got.ok()) return got.status();
      stored = std::move(*got);
    }
    ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(inline_map != nullptr ? *inline_map : stored.map(),
                                                 options_.limits));
    return site;  // the engine checks its geometry (CheckSiteGeometry)
  };
  return source;
}

void CoveragePlannerService::WarmInBackground(const MapSource& source, PlanRequest request) {
  if (draining()) return;
  const bool queued = warm_pool_.TrySubmit([this, source, request]() mutable {
    const absl::Time start = absl::Now();
    request.common.stop = background_stop_.WithEarlierDeadline(start + options_.max_request_time);
    const absl::Status built = engine_.Prepare(source, request);
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

absl::StatusOr<PlanRequest> CoveragePlannerService::EngineRequestFor(const CallInfo& call,
                                                                     const v1::PlanRequest& request,
                                                                     const StopToken& cancel,
                                                                     absl::Time start) const {
  if (drain_cut_.load()) return absl::UnavailableError("server is shutting down; retry on another");
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  ASSIGN_OR_RETURN(PlanRequest plan_request, PlanRequestFromProto(request));
  CommonOptions& options = plan_request.common;

  // The budget: the request's time limit (or the server default), and never
  // past the call's deadline minus the margin kept for sending the reply.
  double budget_s = request.time_limit_s() > 0 ? request.time_limit_s() : options_.default_budget_s;
  StopToken stop = cancel;
  if (call.deadline != absl::InfiniteFuture()) {
    const absl::Time reply_by = call.deadline - options_.deadline_margin;
    if (reply_by <= start && call.start + options_.deadline_margin < call.deadline) {
      // The budget was there on arrival and went into the queue: overload.
      return absl::ResourceExhaustedError(absl::StrFormat(
          "server busy: the call waited %d ms for a worker and has no time left to plan",
          absl::ToInt64Milliseconds(start - call.start)));
    }
    if (reply_by <= start) {
      return absl::DeadlineExceededError(
          absl::StrFormat("deadline of %d ms leaves no time to plan",
                          absl::ToInt64Milliseconds(call.deadline - call.start)));
    }
    stop = cancel.WithEarlierDeadline(reply_by);
    budget_s = std::min(budget_s, absl::ToDoubleSeconds(reply_by - start));
  } else {
    stop = cancel.WithEarlierDeadline(start + options_.max_request_time);
  }
  options.time_limit_s = std::max(budget_s, 1e-3);
  options.stop = stop;
  return plan_request;
}

absl::StatusOr<MapSource> CoveragePlannerService::PlanMapSource(const CallInfo& call,
                                                                const v1::PlanRequest& request) {
  std::string map_id;
  std::shared_ptr<const v1::Map> inline_map;
  switch (request.map_ref_case()) {
    case v1::PlanRequest::kMapId:
      RETURN_IF_ERROR(ValidateMapId(request.map_id()));
      map_id = request.map_id();
      if (!OwnsMap(call.tenant_tag, map_id)) return MapNotFound(map_id);
      // A deleted map, or one found damaged, is not planned from the cache.
      if (absl::Status s = store_->Check(map_id); !s.ok()) {
        return absl::IsNotFound(s) ? MapNotFound(map_id) : s;
      }
      break;
    case v1::PlanRequest::kMap:
      map_id = ComputeMapId(request.map());
      inline_map = std::make_shared<const v1::Map>(request.map());
      break;
    default:
      return absl::InvalidArgumentError("PlanRequest needs map_id or an inline map");
  }
  return SourceFor(map_id, inline_map);
}

absl::Status CoveragePlannerService::RunPlan(const CallInfo& call, const v1::PlanRequest& request,
                                             const StopToken& cancel, v1::PlanResponse* response,
                                             std::shared_ptr<const ServedBody>* served) {
  const absl::Time start = absl::Now();
  ASSIGN_OR_RETURN(PlanRequest plan_request, EngineRequestFor(call, request, cancel, start));
  ASSIGN_OR_RETURN(const MapSource source, PlanMapSource(call, request));
  const std::string& map_id = source.map_id;
  absl::StatusOr<EngineResult> result = engine_.Plan(source, plan_request);
  if (!result.ok()) {
    if (IsStop(result.status()) && !cancel.cancelled() && call.deadline != absl::InfiniteFuture()) {
      // Cut off by this call's deadline: finish the artifacts in the
      // background so the next call finds them cached. (A call without a
      // deadline that hit --max_request_s already had that long.)
      WarmInBackground(source, plan_request);
    }
    if (IsStop(result.status()) && drain_cut_.load()) {
      return absl::UnavailableError(
          "server shut down before a first plan was found; retry on another");
    }
    return IsStop(result.status())
               ? StoppedStatus(result.status(), cancel, call, start, options_.max_request_time)
               : result.status();
  }
  if (result->answered_by != nullptr) {
    if (std::shared_ptr<const ServedBody> reply =
            ServedHitReply(call.tenant_tag, result->answered_by)) {
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
  if (drain_cut_.load() && response->termination().limit() == v1::LIMIT_CANCELLED) {
    response->mutable_termination()->set_detail(absl::StrCat(
        "cut short by the server's drain (shutting down); ", response->termination().detail()));
  }
  if (request.map_ref_case() == v1::PlanRequest::kMapId) PersistPlan(request, *response);
  RecordPlanSolve(start, retained->plan.stats);
  plans_.Put(std::move(retained));
  metrics_->plans_retained().Set(static_cast<double>(plans_.size()));
  // Only plans the store keeps too: a repeated hit is neither retained nor
  // persisted again, so its id must stay resolvable (inline maps are not).
  if (result->answered_by != nullptr && request.map_ref_case() == v1::PlanRequest::kMapId) {
    RememberServedHit(call.tenant_tag, *result, *response);
  }
  return absl::OkStatus();
}

bool CoveragePlannerService::ServeRecalledHit(grpc::ServerUnaryReactor* reactor,
                                              const CallInfo& call, const v1::PlanRequest& request,
                                              const StopToken& cancel,
                                              grpc::ByteBuffer* response_bytes) {
  const absl::Time start = absl::Now();
  absl::StatusOr<PlanRequest> plan_request = EngineRequestFor(call, request, cancel, start);
  if (!plan_request.ok()) return false;
  absl::StatusOr<MapSource> source = PlanMapSource(call, request);
  if (!source.ok()) return false;
  absl::StatusOr<std::optional<Recalled>> recalled = engine_.Recall(*source, *plan_request);
  if (!recalled.ok() || !recalled->has_value()) return false;
  std::shared_ptr<const ServedBody> served = ServedHitReply(call.tenant_tag, (*recalled)->entry);
  if (served == nullptr) return false;
  // As RunPlan answers a repeated hit: the served bytes, then this call's stats.
  v1::PlanResponse response;
  response.mutable_stats()->set_planning_ms((*recalled)->lookup_ms);
  response.mutable_stats()->set_decomposition_cached(true);
  PlanStats solve;  // what the solve metrics read
  solve.plan_source = PlanOrigin::kCacheHit;
  solve.tour_cut_short = (*recalled)->entry->plan.stats.tour_cut_short;
  RecordPlanSolve(start, solve, /*queued=*/false);
  metrics_->hits_without_worker().Increment();
  const std::string detail = absl::StrCat(served->detail, " cached=1");
  FinishCall(reactor, call, SerializePlanReply(response, std::move(served), response_bytes),
             detail);
  return true;
}

void CoveragePlannerService::RecordPlanSolve(absl::Time start, const PlanStats& stats,
                                             bool queued) {
  const int64_t solve_us = absl::ToInt64Microseconds(absl::Now() - start);
  metrics_->RecordSolve(solve_us * 1e-6, stats.tour_cut_short);
  metrics_->RecordPlanSource(PlanOriginName(stats.plan_source));
  if (!queued) return;
  const auto update = [solve_us](std::atomic<int64_t>& mean_us) {
    const int64_t mean = mean_us.load();
    mean_us.store(mean == 0 ? solve_us : (7 * mean + solve_us) / 8);
  };
  update(mean_solve_us_);
  if (stats.plan_source == PlanOrigin::kCacheHit) update(mean_hit_us_);
}

bool CoveragePlannerService::IsHitRequest(uint64_t key) {
  absl::MutexLock lock(&served_mu_);
  return hit_requests_.contains(key);
}

void CoveragePlannerService::NoteHitRequest(uint64_t key, bool hit) {
  absl::MutexLock lock(&served_mu_);
  if (!hit) {
    hit_requests_.erase(key);
    return;
  }
  if (hit_requests_.size() >= kMaxHitRequests) hit_requests_.clear();
  hit_requests_.insert(key);
}

absl::Duration ExpectedQueueWait(int ahead, int hits_ahead, int workers, absl::Duration mean_solve,
                                 absl::Duration mean_hit) {
  workers = std::max(1, workers);
  if (ahead < workers) return absl::ZeroDuration();
  hits_ahead = std::clamp(hits_ahead, 0, ahead);
  const absl::Duration mean = (mean_hit * hits_ahead + mean_solve * (ahead - hits_ahead)) / ahead;
  return mean * (ahead - workers + 1) / workers;
}

std::shared_ptr<const CoveragePlannerService::ServedBody> CoveragePlannerService::ServedHitReply(
    const std::string& tenant_tag, const std::shared_ptr<const RememberedPlan>& entry) {
  std::string plan_id;
  std::shared_ptr<const ServedBody> reply;
  {
    absl::MutexLock lock(&served_mu_);
    auto it = served_.find(ServedHitKey(tenant_tag, entry.get()));
    if (it == served_.end() || it->second.entry.lock() != entry) return nullptr;
    plan_id = it->second.plan_id;
    reply = it->second.reply;
  }
  // Expired from the retained plans (GetPlan would not find it): a new id.
  if (plans_.Get(plan_id) == nullptr) return nullptr;
  return reply;
}

void CoveragePlannerService::RememberServedHit(const std::string& tenant_tag,
                                               const EngineResult& hit,
                                               const v1::PlanResponse& reply) {
  ServedHit served;
  served.entry = hit.answered_by;
  served.plan_id = reply.plan_id();
  served.bytes = reply.ByteSizeLong();
  if (served.bytes > kMaxServedHitBytes / 4) return;  // huge plans: converted per call
  served.reply = ServedBodyFor(reply);
  if (served.reply == nullptr) return;
  const ServedHitKey key(tenant_tag, hit.answered_by.get());
  absl::MutexLock lock(&served_mu_);
  auto [it, inserted] = served_.try_emplace(key);
  if (!inserted) {
    served_bytes_ -= it->second.bytes;
  } else {
    served_order_.push_back(key);
  }
  served_bytes_ += served.bytes;
  it->second = std::move(served);
  // Over a bound: drop the oldest keys (a key replaced in place keeps its place).
  while ((served_.size() > kMaxServedHits || served_bytes_ > kMaxServedHitBytes) &&
         !served_order_.empty()) {
    auto old = served_.find(served_order_.front());
    served_order_.pop_front();
    if (old == served_.end()) continue;
    served_bytes_ -= old->second.bytes;
    served_.erase(old);
  }
}

grpc::ServerUnaryReactor* CoveragePlannerService::Plan(grpc::CallbackServerContext* context,
                                                       const grpc::ByteBuffer* request_bytes,
                                                       grpc::ByteBuffer* response_bytes) {
  auto* reactor = new PlanReactor();
  CallInfo call = StartCall(context, "Plan");
  // Parsed first, as gRPC parses the other methods' requests before their
  // handlers (and their auth checks) run.
  auto request = std::make_shared<v1::PlanRequest>();
  {
    grpc::ByteBuffer bytes = *request_bytes;  // shares the slices; Deserialize consumes it
    if (!grpc::SerializationTraits<v1::PlanRequest>::Deserialize(&bytes, request.get()).ok()) {
      FinishCall(reactor, call,
                 absl::InvalidArgumentError(absl::StrCat("request is not a valid ",
                                                         v1::PlanRequest::descriptor()->full_name(),
                                                         " protobuf message")));
      return reactor;
    }
  }
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (draining()) {
    FinishCall(reactor, call, absl::UnavailableError("server is shutting down"));
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  // The request's bytes, tagged with the tenant: a repeat of a request that
  // was answered from memory is expected to be answered from memory again
  // (only requests by map id, which are small, are remembered).
  std::optional<uint64_t> hit_key;
  if (request->map_ref_case() == v1::PlanRequest::kMapId &&
      request_bytes->Length() <= kMaxHitRequestBytes) {
    std::vector<grpc::Slice> slices;
    if (request_bytes->Dump(&slices).ok()) {
      std::string bytes = call.tenant_tag;
      bytes.push_back('\n');
      for (const grpc::Slice& slice : slices) {
        bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
      }
      hit_key = absl::HashOf(bytes);
    }
  }
  const bool likely_hit = hit_key.has_value() && IsHitRequest(*hit_key);
  // A repeat whose reply was served before takes microseconds: answered
  // here, it neither waits behind searches nor costs a thread hand-off.
  if (likely_hit && ServeRecalledHit(reactor, call, *request, reactor->cancel(), response_bytes)) {
    return reactor;
  }
  const auto reject = [&] {
    FinishCall(reactor, call,
               absl::ResourceExhaustedError(absl::StrFormat(
                   "server busy: %d workers and a queue of %d are full; retry later",
                   options_.worker_threads, options_.max_queue)));
  };
  if (!TryAdmitSolve()) {
    reject();
    return reactor;
  }
  const int hits_ahead = likely_hit ? admitted_hits_.fetch_add(1) : admitted_hits_.load();
  const auto release = [this, likely_hit] {
    if (likely_hit) admitted_hits_.fetch_sub(1);
    ReleaseSolve();
  };
  // Deadline-aware admission: if the expected wait for a worker already
  // reaches the reply-by time, refusing now is more useful to the client
  // than a DEADLINE_EXCEEDED after waiting.
  if (call.deadline != absl::InfiniteFuture()) {
    const int ahead = admitted_.load() - 1;
    const absl::Duration wait = ExpectedQueueWait(ahead, hits_ahead, options_.worker_threads,
                                                  absl::Microseconds(mean_solve_us_.load()),
                                                  absl::Microseconds(mean_hit_us_.load()));
    const absl::Time reply_by = call.deadline - options_.deadline_margin;
    if (ahead >= std::max(1, options_.worker_threads) && absl::Now() + wait >= reply_by) {
      release();
      FinishCall(reactor, call,
                 absl::ResourceExhaustedError(absl::StrFormat(
                     "server busy: expected queue wait of %d ms exceeds the call's deadline; "
                     "retry later",
                     absl::ToInt64Milliseconds(wait))));
      return reactor;
    }
  }
  const bool queued =
      pool_.TrySubmit([this, reactor, call, request, response_bytes, release, hit_key] {
        UpdateQueueGauges();
        metrics_->in_flight().Set(in_flight_.fetch_add(1) + 1);
        const uint64_t solve = TrackSolve(reactor->cancel());
        v1::PlanResponse response;
        std::shared_ptr<const ServedBody> served;
        absl::Status status = RunPlan(call, *request, reactor->cancel(), &response, &served);
        UntrackSolve(solve);
        metrics_->in_flight().Set(in_flight_.fetch_sub(1) - 1);
        release();
        if (status.ok() && hit_key.has_value()) {
          // Remembered while it is answered from memory; forgotten once it is
          // not (the plan or its map was evicted or deleted).
          NoteHitRequest(*hit_key, served != nullptr ||
                                       response.stats().plan_source() == v1::PLAN_SOURCE_CACHE_HIT);
        }
        std::string detail;
        if (status.ok()) {
          detail = absl::StrCat(served != nullptr ? served->detail : PlanDetail(response),
                                " cached=", response.stats().decomposition_cached() ? 1 : 0);
          status = SerializePlanReply(response, std::move(served), response_bytes);
        }
        FinishCall(reactor, call, status, detail);
        MaybeTrimMemory(absl::Now() - call.start);
      });
  UpdateQueueGauges();
  if (!queued) {
    release();
    reject();
  }
  return reactor;
}

grpc::ServerUnaryReactor* CoveragePlannerService::GetPlan(grpc::CallbackServerContext* context,
                                                          const v1::GetPlanRequest* request,
                                                          v1::PlanResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  CallInfo call = StartCall(context, "GetPlan");
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  std::shared_ptr<const RetainedPlan> plan =
      OwnsPlan(call.tenant_tag, request->plan_id()) ? plans_.Get(request->plan_id()) : nullptr;
  metrics_->plans_retained().Set(static_cast<double>(plans_.size()));
  if (plan == nullptr) {
    FinishCall(reactor, call, PlanNotFound(request->plan_id()));
    return reactor;
  }
  RetainedPlanToProto(*plan, response);  // in memory, no blocking
  FinishCall(reactor, call, absl::OkStatus(), QuotePrefix(request->plan_id()));
  return reactor;
}

// ---------------------------------------------------------------- replans

void CoveragePlannerService::PersistPlan(const v1::PlanRequest& origin,
                                         const v1::PlanResponse& plan) {
  v1::InlinePlan record;
  *record.mutable_request() = origin;
  *record.mutable_plan() = plan;
  auto bytes = std::make_shared<std::string>();
  if (!record.SerializeToString(bytes.get())) return;
  const std::string plan_id = plan.plan_id();
  {
    absl::MutexLock lock(&origins_mu_);
    origins_.emplace_back(plan_id, std::make_shared<const v1::PlanRequest>(origin));
    while (origins_.size() > 4 * options_.max_retained_plans + 16) origins_.pop_front();
  }
  // Off the reply's path: the disk write (with its fsyncs) runs on the I/O
  // pool after the answer is on its way.
  const bool queued = SubmitIo([this, bytes, plan_id] {
    if (absl::Status s = store_->PutPlan(plan_id, *bytes); !s.ok()) {
      LogLine("warn", "plan not persisted",
              {{"plan", plan_id}, {"detail", std::string(s.message())}});
      return;
    }
    if (persisted_.fetch_add(1) % 256 == 255) store_->TrimPlans(options_.max_stored_plans);
  });
  if (!queued) LogLine("warn", "plan not persisted: I/O queue full", {{"plan", plan_id}});
}

std::shared_ptr<const RetainedPlan> CoveragePlannerService::FindPlan(const std::string& plan_id,
                                                                     const StopToken& stop,
                                                                     v1::PlanRequest* origin) {
  if (std::shared_ptr<const RetainedPlan> in_memory = plans_.Get(plan_id)) {
    absl::MutexLock lock(&origins_mu_);
    for (auto it = origins_.rbegin(); it != origins_.rend(); ++it) {
      if (it->first == plan_id) {
        *origin = *it->second;
        break;
      }
    }
    return in_memory;
  }
  absl::StatusOr<std::string> bytes = store_->GetPlan(plan_id);
  v1::InlinePlan record;
  const bool stored = bytes.ok() && record.ParseFromString(*bytes);
  if (stored) *origin = record.request();
  if (!stored || record.request().map_ref_case() != v1::PlanRequest::kMapId) return nullptr;
  // After a restart: rebuild the plan on its stored map.
  absl::StatusOr<RetainedPlan> rebuilt =
      RetainedPlanFromInline(record, engine_, SourceFor(record.request().map_id(), nullptr), stop);
  if (!rebuilt.ok()) {
    LogLine("warn", "stored plan could not be rebuilt",
            {{"plan", plan_id}, {"detail", std::string(rebuilt.status().message())}});
    return nullptr;
  }
  rebuilt->plan_id = plan_id;
  auto plan = std::make_shared<const RetainedPlan>(std::move(*rebuilt));
  plans_.Put(plan);
  return plan;
}

absl::Status CoveragePlannerService::RunReplan(const CallInfo& call,
                                               const v1::ReplanRequest& request,
                                               const StopToken& cancel,
                                               v1::ReplanResponse* response) {
  const absl::Time start = absl::Now();
  if (drain_cut_.load()) return absl::UnavailableError("server is shutting down; retry on another");
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  if (call.deadline != absl::InfiniteFuture() &&
      call.deadline - options_.deadline_margin <= start) {
    return absl::DeadlineExceededError(
        absl::StrFormat("deadline of %d ms left no time to replan (it waited %d ms for a worker)",
                        absl::ToInt64Milliseconds(call.deadline - call.start),
                        absl::ToInt64Milliseconds(start - call.start)));
  }
  ASSIGN_OR_RETURN(RobotProgress progress, ProgressFromProto(request.progress()));
  ASSIGN_OR_RETURN(ReplanMethod method, ReplanMethodFromProto(request.method()));
  ReplanOptions options;
  options.method = method;
  options.seed = request.seed();
  // Never late: the call's deadline (less the reply margin) bounds the work;
  // the time to each encounter bounds it further inside the replanner.
  options.stop = call.deadline != absl::InfiniteFuture()
                     ? cancel.WithEarlierDeadline(call.deadline - options_.deadline_margin)
                     : cancel.WithEarlierDeadline(start + options_.max_request_time);
  ResolvedPlan old;
  RETURN_IF_ERROR(
      ResolvePlan(call.tenant_tag, request.plan_id(),
                  request.plan_ref_case() == v1::ReplanRequest::kPlan ? &request.plan() : nullptr,
                  options.stop, &old));
  ASSIGN_OR_RETURN(ReplanResult result,
                   covplan::Replan(*old.plan, progress, ObstaclesFromProto(request.obstacles()),
                                   options, &estimator_));
  if (request.plan_ref_case() == v1::ReplanRequest::kPlanId)
    RecordProgress(request.plan_id(), request.progress());
  KeepReplan(std::move(result), old, call.tenant_tag, response);
  return absl::OkStatus();
}

absl::Status CoveragePlannerService::ResolvePlan(const std::string& tenant_tag,
                                                 const std::string& plan_id,
                                                 const v1::InlinePlan* inline_plan,
                                                 const StopToken& stop, ResolvedPlan* out) {
  if (inline_plan == nullptr) {
    if (plan_id.empty()) return absl::InvalidArgumentError("needs plan_id or an inline plan");
    if (!OwnsPlan(tenant_tag, plan_id)) return PlanNotFound(plan_id);
    out->plan = FindPlan(plan_id, stop, &out->origin);
    if (out->plan == nullptr) return PlanNotFound(plan_id);
    out->has_origin = out->origin.map_ref_case() == v1::PlanRequest::kMapId;
    return absl::OkStatus();
  }
  const v1::PlanRequest& pr = inline_plan->request();
  std::string map_id;
  std::shared_ptr<const v1::Map> inline_map;
  if (pr.map_ref_case() == v1::PlanRequest::kMapId) {
    RETURN_IF_ERROR(ValidateMapId(pr.map_id()));
    map_id = pr.map_id();
    if (!OwnsMap(tenant_tag, map_id)) return MapNotFound(map_id);
  } else if (pr.map_ref_case() == v1::PlanRequest::kMap) {
    map_id = ComputeMapId(pr.map());
    inline_map = std::make_shared<const v1::Map>(pr.map());
  } else {
    return absl::InvalidArgumentError("plan.request needs map_id or an inline map");
  }
  ASSIGN_OR_RETURN(
      RetainedPlan rebuilt,
      RetainedPlanFromInline(*inline_plan, engine_, SourceFor(map_id, inline_map), stop));
  out->plan = std::make_shared<const RetainedPlan>(std::move(rebuilt));
  out->origin = pr;
  out->has_origin = pr.map_ref_case() == v1::PlanRequest::kMapId;
  return absl::OkStatus();
}

void CoveragePlannerService::KeepReplan(ReplanResult result, const ResolvedPlan& old,
                                        const std::string& tenant_tag,
                                        v1::ReplanResponse* response) {
  auto retained = std::make_shared<RetainedPlan>();
  retained->plan_id = NewPlanId(tenant_tag);
  retained->map_id = old.plan->map_id;
  retained->plan = std::move(result.plan);
  retained->area = result.area;
  retained->request = old.plan->request;
  result.plan = retained->plan;
  ReplanToProto(result, *retained, response);
  if (old.has_origin) PersistPlan(old.origin, response->plan());
  plans_.Put(retained);
  metrics_->plans_retained().Set(static_cast<double>(plans_.size()));
  metrics_->RecordReplan(result.stats.method, result.stats.total_ms * 1e-3,
                         static_cast<int>(result.stats.greedy_detours.size()));
  metrics_->SetReplanEstimator(estimator_.coefficients().a, estimator_.coefficients().b,
                               estimator_.coefficients().c, estimator_.num_samples());
  if (result.stats.replanned_encounter >= 0) {
    // Kept across restarts (off the reply's path); a failed write only costs
    // what was learned since.
    auto text = std::make_shared<std::string>(estimator_.Serialize());
    SubmitIo([this, text] {
      if (absl::Status s = store_->PutState(kEstimatorFile, *text); !s.ok()) {
        LogLine("warn", "replan estimator not saved", {{"detail", std::string(s.message())}});
      }
    });
  }
}

grpc::ServerUnaryReactor* CoveragePlannerService::ServeSolve(
    grpc::CallbackServerContext* context, const char* method,
    const google::protobuf::Message* request,
    std::function<absl::Status(const CallInfo&, const StopToken&, std::string* detail)> work) {
  auto* reactor = new PlanReactor();
  CallInfo call = StartCall(context, method);
  if (!call.auth.ok()) {
    FinishCall(reactor, call, call.auth);
    return reactor;
  }
  if (draining()) {
    FinishCall(reactor, call, absl::UnavailableError("server is shutting down"));
    return reactor;
  }
  if (absl::Status s = CheckRequestStrings(*request); !s.ok()) {
    FinishCall(reactor, call, s);
    return reactor;
  }
  if (!TryAdmitSolve()) {
    FinishCall(reactor, call,
               absl::ResourceExhaustedError(absl::StrFormat(
                   "server busy: %d workers and a queue of %d are full; retry later",
                   options_.worker_threads, options_.max_queue)));
    return reactor;
  }
  const bool queued = pool_.TrySubmit([this, reactor, call, work = std::move(work)] {
    metrics_->in_flight().Set(in_flight_.fetch_add(1) + 1);
    const uint64_t solve = TrackSolve(reactor->cancel());
    std::string detail;
    const absl::Status status = work(call, reactor->cancel(), &detail);
    UntrackSolve(solve);
    metrics_->in_flight().Set(in_flight_.fetch_sub(1) - 1);
    ReleaseSolve();
    FinishCall(reactor, call, status, status.ok() ? detail : "");
    MaybeTrimMemory(absl::Now() - call.start);
  });
  if (!queued) {
    ReleaseSolve();
    FinishCall(reactor, call, absl::ResourceExhaustedError("server busy: work queue is full"));
  }
  return reactor;
}

std::string ReplanDetail(const v1::ReplanResponse& r) {
  return absl::StrFormat("plan=%s method=%s encounters=%d detours=%d new_ranks=%d",
                         r.plan().plan_id(), r.replan().method(), r.replan().num_encounters(),
                         r.replan().greedy_detours_size(), r.replan().new_ranks());
}

grpc::ServerUnaryReactor* CoveragePlannerService::Replan(grpc::CallbackServerContext* context,
                                                         const v1::ReplanRequest* request,
                                                         v1::ReplanResponse* response) {
  return ServeSolve(context, "Replan", request,
                    [this, request, response](const CallInfo& call, const StopToken& cancel,
                                              std::string* detail) {
                      absl::Status status = RunReplan(call, *request, cancel, response);
                      if (status.ok()) *detail = ReplanDetail(*response);
                      return status;
                    });
}

grpc::ServerUnaryReactor* CoveragePlannerService::Resume(grpc::CallbackServerContext* context,
                                                         const v1::ResumeRequest* request,
                                                         v1::ReplanResponse* response) {
  return ServeSolve(context, "Resume", request,
                    [this, request, response](const CallInfo& call, const StopToken& cancel,
                                              std::string* detail) {
                      absl::Status status = RunResume(call, *request, cancel, response);
                      if (status.ok()) {
                        *detail = absl::StrCat(ReplanDetail(*response),
                                               " from=", response->replan().progress_source());
                      }
                      return status;
                    });
}

absl::Status CoveragePlannerService::RunResume(const CallInfo& call,
                                               const v1::ResumeRequest& request,
                                               const StopToken& cancel,
                                               v1::ReplanResponse* response) {
  const absl::Time start = absl::Now();
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  if (call.deadline != absl::InfiniteFuture() &&
      call.deadline - options_.deadline_margin <= start) {
    return absl::DeadlineExceededError("the deadline left no time to resume");
  }
  if (request.plan_id().empty())
    return absl::InvalidArgumentError("plan_id: required (the interrupted plan)");
  if (!request.has_pose())
    return absl::InvalidArgumentError("pose: required (where the robot is now)");
  const Pose2 pose{request.pose().x(), request.pose().y(), request.pose().theta()};
  ASSIGN_OR_RETURN(ReplanMethod method, ReplanMethodFromProto(request.method()));
  ReplanOptions options;
  options.method = method;
  options.seed = request.seed();
  options.stop = call.deadline != absl::InfiniteFuture()
                     ? cancel.WithEarlierDeadline(call.deadline - options_.deadline_margin)
                     : cancel.WithEarlierDeadline(start + options_.max_request_time);
  ResolvedPlan old;
  RETURN_IF_ERROR(ResolvePlan(call.tenant_tag, request.plan_id(), nullptr, options.stop, &old));
  v1::RobotProgress at;
  std::string source;
  if (request.has_progress()) {
    at = request.progress();
    source = "request";
  } else if (std::optional<v1::RobotProgress> recorded = RecordedProgress(request.plan_id())) {
    at = *recorded;
    source = "recorded";
  } else {
    at.set_distance_m(0.0);  // nothing reported: nothing counted as covered
    source = "plan_start";
  }
  ASSIGN_OR_RETURN(RobotProgress progress, ProgressFromProto(at));
  double rejoin_m = 0.0;
  absl::StatusOr<ReplanResult> result =
      covplan::Resume(*old.plan, progress, pose, ObstaclesFromProto(request.obstacles()), options,
                      &estimator_, &rejoin_m);
  if (!result.ok()) {
    if (source == "request" || !absl::IsInvalidArgument(result.status()) ||
        absl::StartsWith(result.status().message(), "pose")) {
      return result.status();
    }
    return absl::InvalidArgumentError(
        absl::StrCat("the progress recorded for this plan (", source,
                     ") no longer fits it: ", result.status().message()));
  }
  RecordProgress(request.plan_id(), at);
  KeepReplan(std::move(*result), old, call.tenant_tag, response);
  response->mutable_replan()->set_progress_source(source);
  response->mutable_replan()->set_rejoin_m(rejoin_m);
  return absl::OkStatus();
}

// ---------------------------------------------------------------- sessions

namespace {
// Ends a Drive call at once (draining, or too many sessions).
class RefusedDrive final : public grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent> {
 public:
  explicit RefusedDrive(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};
}  // namespace

grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent>* CoveragePlannerService::Drive(
    grpc::CallbackServerContext* context) {
  const CallInfo call = StartCall(context, "Drive");
  // A session is not a unary call the drain waits for: StartDraining ends it.
  active_calls_.fetch_sub(1);
  if (!call.auth.ok()) {
    RecordCall(call, call.auth);
    return new RefusedDrive(ToGrpc(call.auth));
  }
  if (draining()) {
    metrics_->RecordRequest("Drive", "UNAVAILABLE", 0.0);
    return new RefusedDrive(grpc::Status(grpc::StatusCode::UNAVAILABLE, "server is shutting down"));
  }
  auto* session = new DriveSession(this, context, &sessions_, absl::StrCat("s-", call.request_id),
                                   call.tenant_tag);
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
  LogLine("info", "drive session started", {{"request_id", call.request_id}});
  session->Start();
  return session;
}

absl::StatusOr<CoveragePlannerService::AdoptedPlan> CoveragePlannerService::AdoptPlan(
    const v1::DriveRequest& first, const StopToken& stop, const std::string& tenant_tag) {
  const StopToken bounded = stop.WithEarlierDeadline(absl::Now() + options_.max_request_time);
  ResolvedPlan resolved;
  RETURN_IF_ERROR(
      ResolvePlan(tenant_tag, first.plan_id(),
                  first.plan_ref_case() == v1::DriveRequest::kPlan ? &first.plan() : nullptr,
                  bounded, &resolved));
  AdoptedPlan out;
  out.grid = resolved.plan->plan.grid;
  if (first.plan_ref_case() == v1::DriveRequest::kPlanId) {
    out.plan_id = first.plan_id();
    return out;
  }
  // An inline plan: retained under a new id so the session's replans name it.
  auto retained = std::make_shared<RetainedPlan>(*resolved.plan);
  retained->plan_id = NewPlanId(tenant_tag);
  out.plan_id = retained->plan_id;
  if (resolved.has_origin) {
    v1::PlanResponse proto;
    RetainedPlanToProto(*retained, &proto);
    PersistPlan(resolved.origin, proto);
  }
  plans_.Put(retained);
  return out;
}

bool CoveragePlannerService::SubmitSolve(std::function<void()> work) {
  if (draining() || !TryAdmitSolve()) return false;
  const bool queued = pool_.TrySubmit([this, work = std::move(work)] {
    metrics_->in_flight().Set(in_flight_.fetch_add(1) + 1);
    work();
    metrics_->in_flight().Set(in_flight_.fetch_sub(1) - 1);
    ReleaseSolve();
  });
  if (!queued) ReleaseSolve();
  return queued;
}

void CoveragePlannerService::RecordProgress(const std::string& plan_id,
                                            const v1::RobotProgress& progress) {
  if (plan_id.empty() || plan_id.size() > 64) return;
  bool queue = false;
  {
    absl::MutexLock lock(&progress_mu_);
    progress_[plan_id] = {++progress_clock_, progress};
    progress_dirty_.insert(plan_id);
    const size_t cap = 4 * options_.max_retained_plans + 64;
    while (progress_.size() > cap) {
      auto oldest = progress_.begin();
      for (auto it = progress_.begin(); it != progress_.end(); ++it) {
        if (it->second.first < oldest->second.first) oldest = it;
      }
      progress_dirty_.erase(oldest->first);
      progress_.erase(oldest);
    }
    if (!progress_flush_queued_) queue = progress_flush_queued_ = true;
  }
  if (queue && !SubmitIo([this] { FlushProgress(); })) {
    absl::MutexLock lock(&progress_mu_);
    progress_flush_queued_ = false;  // the next report tries again
  }
}

void CoveragePlannerService::FlushProgress() {
  absl::MutexLock in_order(&progress_write_mu_);
  std::vector<std::pair<std::string, std::string>> writes;
  {
    absl::MutexLock lock(&progress_mu_);
    for (const std::string& id : progress_dirty_) {
      auto it = progress_.find(id);
      if (it != progress_.end()) writes.emplace_back(id, it->second.second.SerializeAsString());
    }
    progress_dirty_.clear();
    progress_flush_queued_ = false;
  }
  // Coalesced: reports that arrive while these are written are flushed by
  // the next task.
  for (const auto& [id, bytes] : writes) {
    if (absl::Status s = store_->PutProgress(id, bytes); !s.ok()) {
      LogLine("warn", "progress not persisted",
              {{"plan", id}, {"detail", std::string(s.message())}});
    }
  }
}

std::optional<v1::RobotProgress> CoveragePlannerService::RecordedProgress(
    const std::string& plan_id) {
  {
    absl::MutexLock lock(&progress_mu_);
    if (auto it = progress_.find(plan_id); it != progress_.end()) return it->second.second;
  }
  absl::StatusOr<std::string> bytes = store_->GetProgress(plan_id);
  v1::RobotProgress progress;
  if (!bytes.ok() || !progress.ParseFromString(*bytes)) return std::nullopt;
  return progress;
}

}  // namespace covplan
