// The covplan.v1.CoveragePlanner service on gRPC's callback API.
//
// Handlers never block gRPC threads: solves run on a bounded WorkerPool,
// PutMap's decoding on a small separate one, GetMap / DeleteMap on a third
// (so cheap reads never wait behind decoding), and the reply
// is sent with Finish() from the worker. Beyond worker_threads + max_queue
// admitted solves, Plan answers RESOURCE_EXHAUSTED at once.
// A Plan's gRPC deadline (minus ServiceOptions::deadline_margin) is its
// anytime budget; a cancelled call cancels its StopToken so the work stops.
// Planning itself is the transport-free PlanningEngine (planner/engine): this
// class converts protos, schedules, and maps statuses. Per-map artifacts
// (grid, coverage area, partition, transitions) live in one ArtifactLru;
// artifacts that a call's deadline cut off are finished on a background
// thread, so later calls for the same map find them cached instead of
// failing the same way forever.
//
//   MapStore store = ...; ServerMetrics metrics;
//   CoveragePlannerService service(ServiceOptions{}, store.get(), &metrics);
//   builder.RegisterService(&service);
//   ...
//   service.StartDraining();  // new PutMap/Plan calls get UNAVAILABLE
//   server->Shutdown(deadline);
//   service.Shutdown();       // finishes queued work, joins the pool
//
// Thread-safety: handlers are called concurrently by gRPC; all state is
// internally synchronised.
#ifndef COVPLAN_SERVER_SERVICE_H_
#define COVPLAN_SERVER_SERVICE_H_

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "absl/container/flat_hash_set.h"
#include "absl/status/status.h"
#include "absl/time/time.h"
#include "api/convert.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/engine/engine.h"
#include "planner/replan/replanner.h"
#include "server/artifact_lru.h"
#include "server/drive_session.h"
#include "server/map_repository.h"
#include "server/map_store.h"
#include "server/metrics.h"
#include "server/plan_registry.h"
#include "server/tenant_tokens.h"
#include "server/worker_pool.h"

namespace covplan {

struct ServiceOptions {
  EngineLimits limits;
  int worker_threads = 2;
  int max_queue = 16;                        // waiting requests beyond the workers
  size_t cache_budget_bytes = 256ull << 20;  // per-map artifact cache
  // Remember plans in that cache (planner/engine/plan_memory.h): identical
  // requests answered at once, new start poses warm-started.
  bool plan_memory = true;
  double default_budget_s =
      CommonOptions::kDefaultTimeLimitS;  // tour search budget without a deadline
  // Without a deadline, the whole call (artifacts included) stops after
  // this long with DEADLINE_EXCEEDED rather than holding a worker forever.
  absl::Duration max_request_time = absl::Seconds(120);
  absl::Duration deadline_margin = absl::Milliseconds(25);  // kept for the reply
  absl::Duration plan_ttl = absl::Minutes(10);
  size_t max_retained_plans = 256;
  // Plans on stored maps are also written to the store (plans/), so a robot
  // resumes its mission with its plan_id after a restart; the newest this
  // many are kept.
  int64_t max_stored_plans = 4096;
  // Drive streaming sessions: how many may be open, and how long one may go
  // without a message before it is ended.
  int max_sessions = 64;
  absl::Duration session_idle = absl::Seconds(120);

  absl::Status Validate() const;
};

// What a handler knows about its call, for logs and metrics.
struct CallInfo {
  const char* method = "";
  std::string request_id;
  absl::Time start;
  absl::Time deadline = absl::InfiniteFuture();
  // With --token_file: the caller's tenant tag (server/tenant_tokens.h), or
  // `auth` says why the call is refused. Empty tag and OK without one.
  std::string tenant_tag;
  absl::Status auth;
};

// One log line's summary of a replan reply.
std::string ReplanDetail(const v1::ReplanResponse& response);

// Plan is a raw method (request and reply as bytes): the service parses the
// request itself, and a repeated hit is sent as the bytes already serialised
// for the first one plus this call's timings, without a protobuf copy.
// The deadline-aware admission's expected queue wait of a call that has
// `ahead` admitted calls before it and `workers` workers: it starts after
// about (ahead - workers + 1) / workers calls, each costing the mean of the
// calls ahead, of which `hits_ahead` are expected to be repeated cache hits
// (`mean_hit` each) and the rest searches (`mean_solve`). Zero when a worker
// is free.
absl::Duration ExpectedQueueWait(int ahead, int hits_ahead, int workers, absl::Duration mean_solve,
                                 absl::Duration mean_hit);

class CoveragePlannerService final
    : public v1::CoveragePlanner::WithRawCallbackMethod_Plan<v1::CoveragePlanner::CallbackService> {
 public:
  // `tokens` (optional, outlives the service): every call must carry a
  // bearer token of a tenant, and sees only that tenant's maps and plans.
  CoveragePlannerService(const ServiceOptions& options, MapRepository* store,
                         ServerMetrics* metrics, const TenantTokens* tokens = nullptr);
  ~CoveragePlannerService() override;

  grpc::ServerUnaryReactor* PutMap(grpc::CallbackServerContext* context,
                                   const v1::PutMapRequest* request,
                                   v1::PutMapResponse* response) override;
  grpc::ServerUnaryReactor* GetMap(grpc::CallbackServerContext* context,
                                   const v1::GetMapRequest* request,
                                   v1::GetMapResponse* response) override;
  grpc::ServerUnaryReactor* ListMaps(grpc::CallbackServerContext* context,
                                     const v1::ListMapsRequest* request,
                                     v1::ListMapsResponse* response) override;
  grpc::ServerUnaryReactor* DeleteMap(grpc::CallbackServerContext* context,
                                      const v1::DeleteMapRequest* request,
                                      v1::DeleteMapResponse* response) override;
  // `request` must parse as a v1::PlanRequest; `response` is a v1::PlanResponse.
  grpc::ServerUnaryReactor* Plan(grpc::CallbackServerContext* context,
                                 const grpc::ByteBuffer* request,
                                 grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* GetPlan(grpc::CallbackServerContext* context,
                                    const v1::GetPlanRequest* request,
                                    v1::PlanResponse* response) override;
  grpc::ServerUnaryReactor* Replan(grpc::CallbackServerContext* context,
                                   const v1::ReplanRequest* request,
                                   v1::ReplanResponse* response) override;
  grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent>* Drive(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* Resume(grpc::CallbackServerContext* context,
                                   const v1::ResumeRequest* request,
                                   v1::ReplanResponse* response) override;

  void StartDraining() {
    draining_.store(true);
    background_stop_.Cancel();
    sessions_.EndAll();
  }
  bool draining() const { return draining_.load(); }
  // Unary calls between arrival and Finish (health and reflection streams
  // are not counted, so they never hold a drain).
  int active_calls() const { return active_calls_.load(); }
  // The end of the drain's grace: every running Plan/Replan is stopped and
  // answers with its best plan so far, its termination detail saying the
  // drain cut it short.
  void CutShortInFlight();
  // Runs what is queued (cancelled calls finish quickly) and joins workers.
  void Shutdown();

  const ArtifactLru& cache() const { return cache_; }

  // Records a call's metrics and logs one line.
  void RecordCall(const CallInfo& call, const absl::Status& status, const std::string& detail = "");
  // Finishes `reactor` with `status`, records metrics and logs one line.
  void FinishCall(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                  const absl::Status& status, const std::string& detail = "");
  // A repeated hit's reply, serialised once (see ServedHit): the reply with
  // planning_ms and decomposition_cached cleared, and its log summary.
  struct ServedBody {
    std::string bytes;
    std::string detail;  // PlanDetail of the reply, without the per-call fields
  };
  // The Plan work proper (runs on a worker). A repeated hit sets `*served`
  // and puts only this call's stats into `response`: the reply is then the
  // bytes of `*served` followed by those of `response` (protobuf merges
  // concatenated messages).
  absl::Status RunPlan(const CallInfo& call, const v1::PlanRequest& request,
                       const StopToken& cancel, v1::PlanResponse* response,
                       std::shared_ptr<const ServedBody>* served);
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
  void UpdateQueueGauges();
  // Whether the request with this key (a hash of the tenant and the request
  // bytes) was answered from memory last time, and recording whether it was.
  bool IsHitRequest(uint64_t key);
  void NoteHitRequest(uint64_t key, bool hit);
  // A Plan's solve metrics and, for a call that went through the worker
  // queue (`queued`), the mean solve times the admission prices queued
  // calls with (a hit answered on the gRPC thread would pull them down).
  void RecordPlanSolve(absl::Time start, const PlanStats& stats, bool queued = true);
  // Repeated cache hits: the reply already sent for the
  // remembered `entry` to this tenant, if that plan is still retained; else
  // null. RememberServedHit records a reply for the next ones.
  std::shared_ptr<const ServedBody> ServedHitReply(
      const std::string& tenant_tag, const std::shared_ptr<const RememberedPlan>& entry);
  void RememberServedHit(const std::string& tenant_tag, const EngineResult& hit,
                         const v1::PlanResponse& reply);
  // The Replan work proper (runs on a worker).
  absl::Status RunReplan(const CallInfo& call, const v1::ReplanRequest& request,
                         const StopToken& cancel, v1::ReplanResponse* response);
  const ReplanEstimator& estimator() const { return estimator_; }
  // The Resume work proper (runs on a worker).
  absl::Status RunResume(const CallInfo& call, const v1::ResumeRequest& request,
                         const StopToken& cancel, v1::ReplanResponse* response);

  // For Drive sessions. A plan named by the session's first message, found
  // (plan_id) or rebuilt and retained (inline), with its grid.
  struct AdoptedPlan {
    std::string plan_id;
    std::shared_ptr<const Grid> grid;
  };
  absl::StatusOr<AdoptedPlan> AdoptPlan(const v1::DriveRequest& first, const StopToken& stop,
                                        const std::string& tenant_tag);
  // Runs `work` on the solve pool under the same admission bound as unary
  // solves; false (and `work` dropped) when the server is full or draining.
  bool SubmitSolve(std::function<void()> work);
  // The robot's latest progress on a plan, kept in memory and written to the
  // store off the caller's path (coalesced), for Resume.
  void RecordProgress(const std::string& plan_id, const v1::RobotProgress& progress);
  // The recorded progress, from memory or the store.
  std::optional<v1::RobotProgress> RecordedProgress(const std::string& plan_id);
  void CountSuperseded() { metrics_->drive_superseded().Increment(); }
  void UpdateSessionGauge() { metrics_->drive_sessions().Set(sessions_.size()); }
  const SessionRegistry& sessions() const { return sessions_; }

 private:
  CallInfo StartCall(grpc::CallbackServerContext* context, const char* method);
  // Runs map-registry work (decode, disk) on the I/O pool; false if full.
  bool SubmitIo(std::function<void()> work);
  // Non-OK when a queued call should not start: it was cancelled, or its
  // deadline passed while it waited.
  absl::Status QueuedTooLong(const CallInfo& call, const StopToken& cancel) const;
  // Admission control for solves: at most worker_threads + max_queue
  // admitted at once. A solve releases its slot just before it replies, so a
  // client that sends its next request on receiving a reply finds the slot
  // free.
  bool TryAdmitSolve();
  void ReleaseSolve();
  absl::Status RunPutMap(const v1::PutMapRequest& request, const std::string& tenant_tag,
                         v1::PutMapResponse* response);
  // The map, inline or from the store, loaded only when an artifact is built.
  MapSource SourceFor(const std::string& map_id, std::shared_ptr<const v1::Map> inline_map);
  // Queues the artifacts of `request` on the background pool (dropped when
  // it is full).
  void WarmInBackground(const MapSource& source, PlanRequest request);
  std::string NewPlanId(const std::string& tenant_tag);
  // Writes the plan (with the original request it continues) to the store;
  // best effort: a failure is logged and counted, the call still succeeds.
  void PersistPlan(const v1::PlanRequest& origin, const v1::PlanResponse& plan);
  // A retained plan from memory, or else from the store (after a restart).
  std::shared_ptr<const RetainedPlan> FindPlan(const std::string& plan_id, const StopToken& stop,
                                               v1::PlanRequest* origin);
  // The plan a Replan / Resume / Drive continues: by id, or inline (rebuilt
  // on its map), with the Plan request its mission started with.
  struct ResolvedPlan {
    std::shared_ptr<const RetainedPlan> plan;
    v1::PlanRequest origin;
    bool has_origin = false;  // on a stored map: its replans are persisted
  };
  absl::Status ResolvePlan(const std::string& tenant_tag, const std::string& plan_id,
                           const v1::InlinePlan* inline_plan, const StopToken& stop,
                           ResolvedPlan* out);
  // Retains (and persists) a replan's result and fills the reply.
  void KeepReplan(ReplanResult result, const ResolvedPlan& old, const std::string& tenant_tag,
                  v1::ReplanResponse* response);
  // A unary solve (Replan, Resume): admission, the pool, the reply.
  grpc::ServerUnaryReactor* ServeSolve(
      grpc::CallbackServerContext* context, const char* method,
      const google::protobuf::Message* request,
      std::function<absl::Status(const CallInfo&, const StopToken&, std::string* detail)> work);
  void FlushProgress();

  const ServiceOptions options_;
  MapRepository* const store_;
  const TenantTokens* const tokens_;
  ServerMetrics* const metrics_;
  ArtifactLru cache_;
  const PlannerRegistry registry_;
  const PlanningEngine engine_;
  PlanRegistry plans_;
  // Learns replan runtimes from this server's solves; kept in the store dir.
  ReplanEstimator estimator_;
  std::atomic<bool> draining_{false};
  std::atomic<bool> drain_cut_{false};
  std::atomic<int> active_calls_{0};
  // The stop tokens of running solves, so the drain can cut them short.
  absl::Mutex solves_mu_;
  std::map<uint64_t, StopToken> solves_ ABSL_GUARDED_BY(solves_mu_);
  uint64_t next_solve_ ABSL_GUARDED_BY(solves_mu_) = 0;
  uint64_t TrackSolve(const StopToken& token);
  // malloc_trim after a call that worked for a while (rate-limited).
  void MaybeTrimMemory(absl::Duration work);
  std::atomic<int64_t> last_trim_ms_{0};
  void UntrackSolve(uint64_t id);
  std::atomic<uint64_t> next_id_{1};
  std::atomic<int> in_flight_{0};
  std::atomic<int> admitted_{0};
  std::atomic<uint64_t> persisted_{0};
  // The Plan request each retained plan's mission started with (for
  // persisting its replans without waiting for the disk), newest last.
  absl::Mutex origins_mu_;
  std::deque<std::pair<std::string, std::shared_ptr<const v1::PlanRequest>>> origins_
      ABSL_GUARDED_BY(origins_mu_);
  // Identical requests answered from memory get the first hit's plan: its
  // plan id (plan ids name immutable plans) and its reply, so a repeated hit
  // sends stored bytes instead of a conversion, a new retained plan (which
  // would push other clients' plans out of `plans_`) and a disk write.
  // Keyed by tenant and remembered entry; the weak pointer tells a live
  // entry from a new one at a reused address. Bounded by count and bytes.
  struct ServedHit {
    std::weak_ptr<const RememberedPlan> entry;
    std::string plan_id;
    std::shared_ptr<const ServedBody> reply;
    size_t bytes = 0;
  };
  using ServedHitKey = std::pair<std::string, const RememberedPlan*>;
  static constexpr size_t kMaxServedHits = 64;
  static constexpr size_t kMaxServedHitBytes = size_t{16} << 20;
  absl::Mutex served_mu_;
  std::map<ServedHitKey, ServedHit> served_ ABSL_GUARDED_BY(served_mu_);
  std::deque<ServedHitKey> served_order_ ABSL_GUARDED_BY(served_mu_);  // oldest first
  size_t served_bytes_ ABSL_GUARDED_BY(served_mu_) = 0;
  // Exponentially weighted mean wall time of a Plan (microseconds), for the
  // deadline-aware admission: a call whose expected queue wait would leave no
  // time to plan before its deadline is refused at once.
  std::atomic<int64_t> mean_solve_us_{0};
  // The same for Plans answered from memory (PLAN_SOURCE_CACHE_HIT) alone,
  // and the admitted Plan calls expected to be such hits: the hash of their
  // request bytes (with the tenant) was answered from memory last time. They
  // are priced at the hits' mean, other calls at the mean of all Plans.
  // Without this, the burst of hits that follows a cold solve was priced at
  // the cold solve's time and partly refused.
  std::atomic<int64_t> mean_hit_us_{0};
  std::atomic<int> admitted_hits_{0};
  static constexpr size_t kMaxHitRequests = 4096;      // then forgotten at once
  static constexpr size_t kMaxHitRequestBytes = 4096;  // larger requests are not keyed
  absl::flat_hash_set<uint64_t> hit_requests_ ABSL_GUARDED_BY(served_mu_);
  // Latest progress per plan (bounded), and those not yet written.
  absl::Mutex progress_mu_;
  std::map<std::string, std::pair<uint64_t, v1::RobotProgress>> progress_
      ABSL_GUARDED_BY(progress_mu_);
  std::set<std::string> progress_dirty_ ABSL_GUARDED_BY(progress_mu_);
  bool progress_flush_queued_ ABSL_GUARDED_BY(progress_mu_) = false;
  uint64_t progress_clock_ ABSL_GUARDED_BY(progress_mu_) = 0;
  // Held by FlushProgress from its snapshot to its last write, so that two
  // flushes on the I/O pool's threads write in the order they took their
  // snapshots (else an older report could land after a newer one).
  absl::Mutex progress_write_mu_ ABSL_ACQUIRED_BEFORE(progress_mu_);
  SessionRegistry sessions_;
  uint64_t id_salt_;
  StopToken background_stop_;  // cancelled when draining or shutting down
  // Last: their threads stop before the rest is destroyed.
  WorkerPool io_pool_;    // PutMap (decoding) and plan/estimator writes
  WorkerPool read_pool_;  // GetMap / DeleteMap: never behind decoding
  WorkerPool pool_;       // Plan solves
  WorkerPool warm_pool_;  // artifacts cut off by a caller's deadline
};

// A repeated hit's stored reply: `reply` serialised with the per-call stats
// fields (planning_ms, decomposition_cached) cleared, so that the call's own
// values, written after it by SerializePlanReply, win even when they are
// zero or false; null if it cannot be serialised.
std::shared_ptr<const CoveragePlannerService::ServedBody> ServedBodyFor(
    const v1::PlanResponse& reply);
// A Plan reply's bytes: `response`'s, after those of `served` if set (a
// repeated hit, whose stored bytes are shared with the slice, not copied).
absl::Status SerializePlanReply(const v1::PlanResponse& response,
                                std::shared_ptr<const CoveragePlannerService::ServedBody> served,
                                grpc::ByteBuffer* out);

}  // namespace covplan

#endif  // COVPLAN_SERVER_SERVICE_H_
