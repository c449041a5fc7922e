// Admission of solves (Plan, Replan, Resume, a Drive session's replans) to
// the solve pool, decided when a call arrives: per tenant at most its
// max_solves + max_queued admitted at once (server/tenant_quotas.h), in all
// at most worker_threads + max_queue, a
// Plan with a deadline refused at once when the expected queue wait already
// reaches it (queue pricing), the running solves counted (in-flight gauge)
// and tracked so the end of a drain can cut them short. The pool runs at
// most max_solves of a tenant's solves at once, and tenants take turns for
// free workers (server/worker_pool.h), so a busy tenant's queue is not in
// front of another tenant's call.
//
//   if (absl::Status s = admission.AdmitPlan(call, likely_hit); !s.ok()) return Refuse(s);
//   auto outcome = std::make_shared<Outcome>();
//   if (!admission.Submit({[=] { outcome->status = Solve(); }, [=] { Reply(*outcome); },
//                          cancel, likely_hit, call.tenant_tag})) {
//     Refuse(...);  // the pool is full; the slot was released
//   }
//
// A solve releases its slot just before it replies, so a client that sends
// its next request on receiving a reply finds the slot free.
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_ADMISSION_H_
#define COVPLAN_SERVER_ADMISSION_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "server/call_info.h"
#include "server/metrics.h"
#include "server/service_options.h"
#include "server/tenant_quotas.h"
#include "server/worker_pool.h"

namespace covplan {

// The deadline-aware admission's expected queue wait of a call that has
// `ahead` admitted calls before it and `workers` workers: it starts after
// about (ahead - workers + 1) / workers calls, each costing the mean of the
// calls ahead, of which `hits_ahead` are expected to be repeated cache hits
// (`mean_hit` each) and the rest searches (`mean_solve`). Zero when a worker
// is free.
absl::Duration ExpectedQueueWait(int ahead, int hits_ahead, int workers, absl::Duration mean_solve,
                                 absl::Duration mean_hit);

// Non-OK when a queued call should not start: it was cancelled, or its
// deadline passed while it waited.
absl::Status QueuedTooLong(const CallInfo& call, const StopToken& cancel);

// The answer when a pool's queue refuses a task.
absl::Status WorkQueueFull();

class SolveAdmission {
 public:
  // `pool` and `quotas` (outlive this) run the solves and bound each
  // tenant's share.
  SolveAdmission(const ServiceOptions& options, ServerMetrics* metrics, WorkerPool* pool,
                 const TenantQuotas* quotas);

  // Takes a slot of the call's tenant: OK, or RESOURCE_EXHAUSTED naming the
  // quota when the tenant has max_solves + max_queued solves admitted, or
  // when every worker and queue place is taken.
  absl::Status Admit(const CallInfo& call);
  // Admit, for a Plan: `likely_hit` counts it among the calls expected to
  // be answered from memory until its Release; with a deadline, refused
  // (slot released) when the expected queue wait leaves no time to plan.
  absl::Status AdmitPlan(const CallInfo& call, bool likely_hit);
  // Gives a slot of the tenant with `tenant_tag` back (`likely_hit` as it
  // was admitted).
  void Release(const std::string& tenant_tag, bool likely_hit = false);
  // The RESOURCE_EXHAUSTED of a full server (every worker and queue place).
  absl::Status Full() const;

  // What an admitted solve does on a worker.
  struct Task {
    std::function<void()> solve;  // counted in flight while it runs
    std::function<void()> reply;  // after the slot is released (may be empty)
    // Cancelled when the drain's grace ends (none: not cut short).
    std::optional<StopToken> cut_short;
    bool likely_hit = false;  // as admitted
    std::string tenant_tag;   // as admitted
  };
  // Queues an admitted task; false (slot released, nothing run) when the
  // pool is full.
  bool Submit(Task task);

  // The end of the drain's grace: every tracked solve is cancelled, and so
  // is every one that starts from now on.
  void CutShortInFlight();
  bool drain_cut() const { return drain_cut_.load(); }

  // A Plan's wall time, for the means queued calls are priced with; hits
  // (answered from memory) also count towards the hits' own mean.
  void RecordPlanTime(absl::Duration took, bool hit);
  // The queue-depth gauge from the pool's queue.
  void UpdateQueueGauge();
  // malloc_trim after a call that worked for a while (rate-limited), only
  // while no solve runs or waits.
  void TrimMemoryIfIdle(absl::Duration work);

 private:
  // Admit; `ahead`: the admitted calls expected to start before this one
  // (its tenant's own and, as tenants take turns, at most one more of each
  // other tenant's).
  absl::Status AdmitCounted(const CallInfo& call, int* ahead);
  absl::Status OverQuota(const CallInfo& call, const TenantQuota& quota) const;
  void ReleaseTenant(const std::string& tenant_tag);
  uint64_t Track(const StopToken& token);
  void Untrack(uint64_t id);

  const ServiceOptions& options_;
  ServerMetrics* const metrics_;
  WorkerPool* const pool_;
  const TenantQuotas* const quotas_;
  // Solves admitted per tenant tag (queued or running), for the quotas.
  absl::Mutex tenants_mu_;
  std::map<std::string, int> admitted_by_tenant_ ABSL_GUARDED_BY(tenants_mu_);
  std::atomic<int> admitted_{0};
  std::atomic<int> in_flight_{0};
  std::atomic<bool> drain_cut_{false};
  // The stop tokens of running solves, so the drain can cut them short.
  absl::Mutex solves_mu_;
  std::map<uint64_t, StopToken> solves_ ABSL_GUARDED_BY(solves_mu_);
  uint64_t next_solve_ ABSL_GUARDED_BY(solves_mu_) = 0;
  // Exponentially weighted mean wall time of a Plan (microseconds), for the
  // deadline-aware admission: a call whose expected queue wait would leave no
  // time to plan before its deadline is refused at once.
  std::atomic<int64_t> mean_solve_us_{0};
  // The same for Plans answered from memory (PLAN_SOURCE_CACHE_HIT) alone,
  // and the admitted Plan calls expected to be such hits (see
  // ServedReplies::IsHitRequest). They are priced at the hits' mean, other
  // calls at the mean of all Plans. Without this, the burst of hits that
  // follows a cold solve was priced at the cold solve's time and partly
  // refused.
  std::atomic<int64_t> mean_hit_us_{0};
  std::atomic<int> admitted_hits_{0};
  std::atomic<int64_t> last_trim_ms_{0};
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_ADMISSION_H_
