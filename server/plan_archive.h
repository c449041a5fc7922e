// The plans the service keeps: retained plans (PlanRegistry: GetPlan, and
// what Replan, Resume and Drive continue), the Plan request each mission
// started with (its origin), their records in the MapRepository so a robot
// resumes its mission after a restart, and the replan estimator learned
// from this server's solves (kept in the store's state). Writes run on the
// I/O pool, off the reply's path, and are best effort: a failure is logged,
// the call still succeeds.
//
//   PlanArchive archive(options, store, metrics, &engine, &io_pool);
//   archive.Put(plan);
//   archive.Persist(origin, reply);  // plans on stored maps only
//   std::shared_ptr<const RetainedPlan> p = archive.Find(plan_id, stop, &origin);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_PLAN_ARCHIVE_H_
#define COVPLAN_SERVER_PLAN_ARCHIVE_H_

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "planner/replan/replanner.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/plan_registry.h"
#include "server/service_options.h"
#include "server/worker_pool.h"

namespace covplan {

// A new plan id: 128 bits from the kernel's CSPRNG (an id cannot be guessed
// from another one), scoped to the tenant.
std::string NewPlanId(const std::string& tenant_tag);

class PlanArchive {
 public:
  // Trims the stored plans and loads the estimator the store kept. `engine`
  // rebuilds stored plans; `io_pool` runs the writes (both outlive this).
  PlanArchive(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics,
              const PlanningEngine* engine, WorkerPool* io_pool);

  // The retained plan, or null once it expired.
  std::shared_ptr<const RetainedPlan> Get(const std::string& plan_id) {
    return plans_.Get(plan_id);
  }
  void Put(std::shared_ptr<const RetainedPlan> plan) { plans_.Put(std::move(plan)); }
  // The plans-retained gauge.
  void PublishRetainedCount();

  // Writes the plan (with the original request it continues) to the store.
  void Persist(const v1::PlanRequest& origin, const v1::PlanResponse& plan);
  // A retained plan from memory, or else from the store (after a restart,
  // rebuilt on its stored map and retained again), with its origin.
  std::shared_ptr<const RetainedPlan> Find(const std::string& plan_id, const StopToken& stop,
                                           v1::PlanRequest* origin);

  ReplanEstimator* mutable_estimator() { return &estimator_; }
  const ReplanEstimator& estimator() const { return estimator_; }
  // The estimator's gauges.
  void PublishEstimator();
  // Keeps the estimator across restarts; a failed write only costs what was
  // learned since.
  void SaveEstimator();

 private:
  const ServiceOptions& options_;
  MapRepository* const store_;
  ServerMetrics* const metrics_;
  const PlanningEngine* const engine_;
  WorkerPool* const io_pool_;
  PlanRegistry plans_;
  // Learns replan runtimes from this server's solves; kept in the store.
  ReplanEstimator estimator_;
  std::atomic<uint64_t> persisted_{0};
  // The Plan request each retained plan's mission started with (for
  // persisting its replans without waiting for the disk), newest last.
  absl::Mutex origins_mu_;
  std::deque<std::pair<std::string, std::shared_ptr<const v1::PlanRequest>>> origins_
      ABSL_GUARDED_BY(origins_mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PLAN_ARCHIVE_H_
