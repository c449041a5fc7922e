#include "server/admission.h"

#include <malloc.h>

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
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
                               WorkerPool* pool)
    : options_(options), metrics_(metrics), pool_(pool) {}

absl::Status SolveAdmission::Admit() {
  const int capacity = options_.worker_threads + options_.max_queue;
  int admitted = admitted_.load();
  while (admitted < capacity) {
    if (admitted_.compare_exchange_weak(admitted, admitted + 1)) return absl::OkStatus();
  }
  return Full();
}

absl::Status SolveAdmission::Full() const {
  return absl::ResourceExhaustedError(
      absl::StrFormat("server busy: %d workers and a queue of %d are full; retry later",
                      options_.worker_threads, options_.max_queue));
}

absl::Status SolveAdmission::AdmitPlan(const CallInfo& call, bool likely_hit) {
  if (absl::Status s = Admit(); !s.ok()) return s;
  const int hits_ahead = likely_hit ? admitted_hits_.fetch_add(1) : admitted_hits_.load();
  // Deadline-aware admission: if the expected wait for a worker already
  // reaches the reply-by time, refusing now is more useful to the client
  // than a DEADLINE_EXCEEDED after waiting.
  if (call.deadline == absl::InfiniteFuture()) return absl::OkStatus();
  const int ahead = admitted_.load() - 1;
  const absl::Duration wait = ExpectedQueueWait(ahead, hits_ahead, options_.worker_threads,
                                                absl::Microseconds(mean_solve_us_.load()),
                                                absl::Microseconds(mean_hit_us_.load()));
  const absl::Time reply_by = call.deadline - options_.deadline_margin;
  if (ahead >= std::max(1, options_.worker_threads) && absl::Now() + wait >= reply_by) {
    Release(likely_hit);
    return absl::ResourceExhaustedError(absl::StrFormat(
        "server busy: expected queue wait of %d ms exceeds the call's deadline; retry later",
        absl::ToInt64Milliseconds(wait)));
  }
  return absl::OkStatus();
}

void SolveAdmission::Release(bool likely_hit) {
  if (likely_hit) admitted_hits_.fetch_sub(1);
  admitted_.fetch_sub(1);
}

bool SolveAdmission::Submit(Task task) {
  const bool likely_hit = task.likely_hit;
  const bool queued = pool_->TrySubmit([this, task = std::move(task)] {
    metrics_->in_flight().Set(in_flight_.fetch_add(1) + 1);
    std::optional<uint64_t> tracked;
    if (task.cut_short.has_value()) tracked = Track(*task.cut_short);
    task.solve();
    if (tracked.has_value()) Untrack(*tracked);
    metrics_->in_flight().Set(in_flight_.fetch_sub(1) - 1);
    Release(task.likely_hit);
    if (task.reply) task.reply();
  });
  if (!queued) Release(likely_hit);
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
