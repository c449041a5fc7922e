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
//   archive.PutAlias(fresh_id, retained->plan_id);  // a repeated hit's own id
//   std::shared_ptr<const RetainedPlan> p = archive.Find(plan_id, stop, &origin);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_PLAN_ARCHIVE_H_
#define COVPLAN_SERVER_PLAN_ARCHIVE_H_

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_map.h"
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

  // The retained plan, or null once it expired (an alias used for the
  // first time is stored then: see PutAlias).
  std::shared_ptr<const RetainedPlan> Get(const std::string& plan_id);
  void Put(std::shared_ptr<const RetainedPlan> plan) { plans_.Put(std::move(plan)); }
  // The plans-retained gauge.
  void PublishRetainedCount();

  // Writes the plan (with the original request it continues) to the store,
  // on the I/O pool.
  void Persist(const v1::PlanRequest& origin, const v1::PlanResponse& plan);
  // The same write, waited for (up to kPersistNowWait): a replan is stored
  // before its robot receives it, so a robot whose replica dies continues on
  // another from the newest plan it holds (docs/robustness.md, "Drive
  // sessions that outlive their replica"). A failed write is logged, as
  // Persist's; a slower one goes on after the wait; the call still succeeds.
  void PersistNow(const v1::PlanRequest& origin, const v1::PlanResponse& plan);
  static constexpr absl::Duration kPersistNowWait = absl::Milliseconds(250);
  // Names `original_id`'s plan `alias_id` too, a mission of its own (a
  // repeated Plan answered from memory), retained as an alias that starts
  // from the original's origin. When the alias is first used (Get, Find),
  // a plan the store keeps is stored for it too, as a small record naming
  // the original ("the plan of <original>"), written coalesced off the
  // caller's path (at most kMaxPendingAliases wait; the rest are logged);
  // the original's record is touched after its aliases', so the store trims
  // it after them. Aliases never used are stored when the service shuts
  // down (StoreUnusedAliases), not one by one: a flood of repeats neither
  // loads the disk nor pushes stored missions out. A SIGKILL loses the
  // unused ones (their robots plan again).
  void PutAlias(const std::string& alias_id, const std::string& original_id);
  // Stores every live alias never used (a drain's last step), at once.
  void StoreUnusedAliases();
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
  static constexpr size_t kMaxPendingAliases = 4096;
  struct PendingAlias {
    std::string alias_id;
    std::string original_id;
    std::string record;  // a serialised v1::InlinePlan
  };
  // The stored record of `plan` (null if it does not serialise); remembers
  // its origin.
  std::shared_ptr<std::string> Record(const v1::PlanRequest& origin, const v1::PlanResponse& plan);
  // Stores a record (a failure is logged) and trims the store now and then.
  void Write(const std::string& plan_id, const std::string& bytes);
  void RememberOrigin(const std::string& plan_id, std::shared_ptr<const v1::PlanRequest> origin);
  // The origin of `plan_id`, or of the original it is an alias of; false
  // when none is known.
  bool OriginOf(const std::string& plan_id, v1::PlanRequest* origin);
  // An alias's first use: stored if its original was (its origin is known).
  void AliasUsed(const std::string& alias_id, const std::string& original_id);
  // Stores `records` (alias id, record) and touches their originals.
  void StoreAliases(const std::vector<std::pair<std::string, std::string>>& records,
                    const std::set<std::string>& originals);
  // Writes the pending aliases (on the I/O pool).
  void FlushAliases();
  // A stored plan rebuilt on its stored map and retained; an alias record
  // (`depth` 0 only) rebuilds its original under the alias's id.
  std::shared_ptr<const RetainedPlan> Load(const std::string& plan_id, const StopToken& stop,
                                           v1::PlanRequest* origin, int depth);

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
  // Bounded by count: four per retained plan (its replans') and one per
  // alias (PlanRegistry keeps 16 per retained plan).
  absl::flat_hash_map<std::string, std::shared_ptr<const v1::PlanRequest>> origins_
      ABSL_GUARDED_BY(origins_mu_);
  std::deque<std::string> origin_order_ ABSL_GUARDED_BY(origins_mu_);  // oldest first
  absl::Mutex aliases_mu_;
  std::deque<PendingAlias> pending_aliases_ ABSL_GUARDED_BY(aliases_mu_);
  bool alias_flush_queued_ ABSL_GUARDED_BY(aliases_mu_) = false;
  std::atomic<uint64_t> aliases_not_stored_{0};  // for the log
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PLAN_ARCHIVE_H_
