#include "server/admission.h"

#include <malloc.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "server/log.h"

namespace covplan {
namespace {

// Calls that worked this long are followed by a malloc_trim.
constexpr absl::Duration kTrimAfterWork = absl::Milliseconds(50);

}  // namespace

absl::Duration ExpectedQueueWait(int ahead, int hits_ahead, int workers, absl::Duration mean_solve,
                                 absl::Duration mean_hit) {
  workers = std::max(1, workers);
  if (ahead < workers) return absl::ZeroDuration();
  hits_ahead = std::clamp(hits_ahead, 0, ahead);
  const absl::Duration mean = (mean_hit * hits_ahead + mean_solve * (ahead - hits_ahead)) / ahead;
  return mean * (ahead - workers + 1) / workers;
}

absl::Status QueuedTooLong(const CallInfo& call, const StopToken& cancel) {
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

absl::Status WorkQueueFull() {
  return absl::ResourceExhaustedError("server busy: work queue is full");
}

SolveAdmission::SolveAdmission(const ServiceOptions& options, ServerMetrics* metrics,
                               WorkerPool* pool, const TenantQuotas* quotas)
    : options_(options), metrics_(metrics), pool_(pool), quotas_(quotas) {}

absl::Status SolveAdmission::Admit(const CallInfo& call) {
  int ahead = 0;
  return AdmitCounted(call, &ahead);
}

absl::Status SolveAdmission::AdmitCounted(const CallInfo& call, int* ahead) {
  const TenantQuota quota = quotas_->For(call.tenant_tag);
  {
    absl::MutexLock lock(&tenants_mu_);
    int& mine = admitted_by_tenant_[call.tenant_tag];
    if (quota.max_queued > 0 || quota.max_solves > 0) {
      const int running = quota.max_solves > 0 ? quota.max_solves : options_.worker_threads;
      const int queued = quota.max_queued > 0 ? quota.max_queued : options_.max_queue;
      if (mine >= running + queued) {
        if (mine == 0) admitted_by_tenant_.erase(call.tenant_tag);
        return OverQuota(call, quota);
      }
    }
    // Tenants take turns: ahead of this call are the tenant's own admitted
    // calls and, of every other tenant, at most one more than those.
    *ahead = mine;
    for (const auto& [tag, count] : admitted_by_tenant_) {
      if (tag != call.tenant_tag) *ahead += std::min(count, mine + 1);
    }
    ++mine;
  }
  const int capacity = options_.worker_threads + options_.max_queue;
  int admitted = admitted_.load();
  while (admitted < capacity) {
    if (admitted_.compare_exchange_weak(admitted, admitted + 1)) return absl::OkStatus();
  }
  ReleaseTenant(call.tenant_tag);
  return Full();
}

absl::Status SolveAdmission::OverQuota(const CallInfo& call, const TenantQuota& quota) const {
  std::vector<std::string> limits;
  if (quota.max_solves > 0) limits.push_back(absl::StrCat(quota.max_solves, " running"));
  if (quota.max_queued > 0) limits.push_back(absl::StrCat(quota.max_queued, " queued"));
  return absl::ResourceExhaustedError(absl::StrCat(
      call.tenant.empty() ? std::string("this tenant") : absl::StrCat("tenant ", call.tenant),
      " is over its quota of ", absl::StrJoin(limits, " and "),
      " solves (--tenant_max_solves, --tenant_max_queued or its line in --tenant_quota_file); "
      "retry later"));
}

void SolveAdmission::ReleaseTenant(const std::string& tenant_tag) {
  absl::MutexLock lock(&tenants_mu_);
  const auto it = admitted_by_tenant_.find(tenant_tag);
  if (it != admitted_by_tenant_.end() && --it->second <= 0) admitted_by_tenant_.erase(it);
}

absl::Status SolveAdmission::Full() const {
  return absl::ResourceExhaustedError(
      absl::StrFormat("server busy: %d workers and a queue of %d are full; retry later",
                      options_.worker_threads, options_.max_queue));
}

absl::Status SolveAdmission::AdmitPlan(const CallInfo& call, bool likely_hit) {
  int fair_ahead = 0;
  if (absl::Status s = AdmitCounted(call, &fair_ahead); !s.ok()) return s;
  const int hits_ahead = likely_hit ? admitted_hits_.fetch_add(1) : admitted_hits_.load();
  // Deadline-aware admission: if the expected wait for a worker already
  // reaches the reply-by time, refusing now is more useful to the client
  // than a DEADLINE_EXCEEDED after waiting.
  if (call.deadline == absl::InfiniteFuture()) return absl::OkStatus();
  const int ahead = std::min(fair_ahead, admitted_.load() - 1);
  const absl::Duration wait = ExpectedQueueWait(ahead, hits_ahead, options_.worker_threads,
                                                absl::Microseconds(mean_solve_us_.load()),
                                                absl::Microseconds(mean_hit_us_.load()));
  const absl::Time reply_by = call.deadline - options_.deadline_margin;
  if (ahead >= std::max(1, options_.worker_threads) && absl::Now() + wait >= reply_by) {
    Release(call.tenant_tag, likely_hit);
    return absl::ResourceExhaustedError(absl::StrFormat(
        "server busy: expected queue wait of %d ms exceeds the call's deadline; retry later",
        absl::ToInt64Milliseconds(wait)));
  }
  return absl::OkStatus();
}

void SolveAdmission::Release(const std::string& tenant_tag, bool likely_hit) {
  if (likely_hit) admitted_hits_.fetch_sub(1);
  admitted_.fetch_sub(1);
  ReleaseTenant(tenant_tag);
}

bool SolveAdmission::Submit(Task task) {
  const bool likely_hit = task.likely_hit;
  const std::string tenant_tag = task.tenant_tag;
  const int max_running = quotas_->For(tenant_tag).max_solves;
  auto run = [this, task = std::move(task)] {
    metrics_->in_flight().Set(in_flight_.fetch_add(1) + 1);
    std::optional<uint64_t> tracked;
    if (task.cut_short.has_value()) tracked = Track(*task.cut_short);
    task.solve();
    if (tracked.has_value()) Untrack(*tracked);
    metrics_->in_flight().Set(in_flight_.fetch_sub(1) - 1);
    Release(task.tenant_tag, task.likely_hit);
    if (task.reply) task.reply();
  };
  const bool queued = pool_->TrySubmit(std::move(run), tenant_tag, max_running);
  if (!queued) Release(tenant_tag, likely_hit);
  return queued;
}

uint64_t SolveAdmission::Track(const StopToken& token) {
  absl::MutexLock lock(&solves_mu_);
  const uint64_t id = next_solve_++;
  solves_.emplace(id, token);
  if (drain_cut_.load()) token.Cancel();
  return id;
}

void SolveAdmission::Untrack(uint64_t id) {
  absl::MutexLock lock(&solves_mu_);
  solves_.erase(id);
}

void SolveAdmission::CutShortInFlight() {
  absl::MutexLock lock(&solves_mu_);
  drain_cut_.store(true);
  for (const auto& [id, token] : solves_) token.Cancel();
  if (!solves_.empty()) {
    LogLine("warn", "drain grace over: cutting running solves short",
            {{"solves", absl::StrCat(solves_.size())}});
  }
}

void SolveAdmission::RecordPlanTime(absl::Duration took, bool hit) {
  const int64_t solve_us = absl::ToInt64Microseconds(took);
  const auto update = [solve_us](std::atomic<int64_t>& mean_us) {
    const int64_t mean = mean_us.load();
    mean_us.store(mean == 0 ? solve_us : (7 * mean + solve_us) / 8);
  };
  update(mean_solve_us_);
  if (hit) update(mean_hit_us_);
}

void SolveAdmission::UpdateQueueGauge() { metrics_->queue_depth().Set(pool_->queued()); }

void SolveAdmission::TrimMemoryIfIdle(absl::Duration work) {
  // Large solves and decodes leave freed pages in glibc's arenas; give them
  // back (off the reply's path, when idle, at most every 100 ms) so resident memory
  // follows the budgets instead of the high-water mark.
  if (work < kTrimAfterWork) return;
  // malloc_trim locks every arena in turn: only when no solve runs or waits,
  // so it never stalls a call that is racing its deadline.
  if (in_flight_.load() != 0 || pool_->queued() != 0) return;
  const int64_t now_ms = absl::ToUnixMillis(absl::Now());
  int64_t last = last_trim_ms_.load();
  if (now_ms - last < 100 || !last_trim_ms_.compare_exchange_strong(last, now_ms)) return;
  ::malloc_trim(0);
}

}  // namespace covplan
