// The covplan.v1.CoveragePlanner service on gRPC's callback API.
//
// Handlers never block gRPC threads: solves run on a bounded WorkerPool,
// map-registry work (decoding, disk) on a small separate one, and the reply
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
#include <deque>
#include <utility>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "api/convert.h"
#include "planner/engine/engine.h"
#include "planner/replan/replanner.h"
#include "server/artifact_lru.h"
#include "server/map_repository.h"
#include "server/map_store.h"
#include "server/metrics.h"
#include "server/plan_registry.h"
#include "server/worker_pool.h"

namespace covplan {

struct ServiceOptions {
  InputLimits limits;
  int worker_threads = 2;
  int max_queue = 16;                        // waiting requests beyond the workers
  size_t cache_budget_bytes = 256ull << 20;  // per-map artifact cache
  double default_budget_s = 2.0;             // tour search budget without a deadline
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

  absl::Status Validate() const;
};

// What a handler knows about its call, for logs and metrics.
struct CallInfo {
  const char* method = "";
  std::string request_id;
  absl::Time start;
  absl::Time deadline = absl::InfiniteFuture();
};

class CoveragePlannerService final : public v1::CoveragePlanner::CallbackService {
 public:
  CoveragePlannerService(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics);
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
  grpc::ServerUnaryReactor* Plan(grpc::CallbackServerContext* context,
                                 const v1::PlanRequest* request,
                                 v1::PlanResponse* response) override;
  grpc::ServerUnaryReactor* GetPlan(grpc::CallbackServerContext* context,
                                    const v1::GetPlanRequest* request,
                                    v1::PlanResponse* response) override;
  grpc::ServerUnaryReactor* Replan(grpc::CallbackServerContext* context,
                                   const v1::ReplanRequest* request,
                                   v1::ReplanResponse* response) override;

  void StartDraining() {
    draining_.store(true);
    background_stop_.Cancel();
  }
  bool draining() const { return draining_.load(); }
  // Runs what is queued (cancelled calls finish quickly) and joins workers.
  void Shutdown();

  const ArtifactLru& cache() const { return cache_; }

  // Finishes `reactor` with `status`, records metrics and logs one line.
  void FinishCall(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                  const absl::Status& status, const std::string& detail = "");
  // The Plan work proper (runs on a worker).
  absl::Status RunPlan(const CallInfo& call, const v1::PlanRequest& request,
                       const StopToken& cancel, v1::PlanResponse* response);
  void UpdateQueueGauges();
  // The Replan work proper (runs on a worker).
  absl::Status RunReplan(const CallInfo& call, const v1::ReplanRequest& request,
                         const StopToken& cancel, v1::ReplanResponse* response);
  const ReplanEstimator& estimator() const { return estimator_; }

 private:
  CallInfo StartCall(grpc::CallbackServerContext* context, const char* method);
  // Runs map-registry work (decode, disk) on the I/O pool; false if full.
  bool SubmitIo(std::function<void()> work);
  // Admission control for solves: at most worker_threads + max_queue
  // admitted at once. A solve releases its slot just before it replies, so a
  // client that sends its next request on receiving a reply finds the slot
  // free.
  bool TryAdmitSolve();
  void ReleaseSolve();
  absl::Status RunPutMap(const v1::PutMapRequest& request, v1::PutMapResponse* response);
  // The map, inline or from the store, loaded only when an artifact is built.
  MapSource SourceFor(const std::string& map_id, std::shared_ptr<const v1::Map> inline_map);
  // Queues the artifacts of `request` on the background pool (dropped when
  // it is full).
  void WarmInBackground(const MapSource& source, PlanRequest request);
  std::string NewPlanId();
  // Writes the plan (with the original request it continues) to the store;
  // best effort: a failure is logged and counted, the call still succeeds.
  void PersistPlan(const v1::PlanRequest& origin, const v1::PlanResponse& plan);
  // A retained plan from memory, or else from the store (after a restart).
  std::shared_ptr<const RetainedPlan> FindPlan(const std::string& plan_id, const StopToken& stop,
                                               v1::PlanRequest* origin);

  const ServiceOptions options_;
  MapRepository* const store_;
  ServerMetrics* const metrics_;
  ArtifactLru cache_;
  const PlannerRegistry registry_;
  const PlanningEngine engine_;
  PlanRegistry plans_;
  // Learns replan runtimes from this server's solves; kept in the store dir.
  ReplanEstimator estimator_;
  std::atomic<bool> draining_{false};
  std::atomic<uint64_t> next_id_{1};
  std::atomic<int> in_flight_{0};
  std::atomic<int> admitted_{0};
  std::atomic<uint64_t> persisted_{0};
  // The Plan request each retained plan's mission started with (for
  // persisting its replans without waiting for the disk), newest last.
  absl::Mutex origins_mu_;
  std::deque<std::pair<std::string, std::shared_ptr<const v1::PlanRequest>>> origins_
      ABSL_GUARDED_BY(origins_mu_);
  // Exponentially weighted mean wall time of a solve (microseconds), for the
  // deadline-aware admission: a call whose expected queue wait would leave no
  // time to plan before its deadline is refused at once.
  std::atomic<int64_t> mean_solve_us_{0};
  uint64_t id_salt_;
  StopToken background_stop_;  // cancelled when draining or shutting down
  // Last: their threads stop before the rest is destroyed.
  WorkerPool io_pool_;    // PutMap / GetMap / DeleteMap
  WorkerPool pool_;       // Plan solves
  WorkerPool warm_pool_;  // artifacts cut off by a caller's deadline
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_SERVICE_H_
