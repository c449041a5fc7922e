// Cooperative cancellation and deadline for long-running planner stages.
//
// A StopToken combines an absolute deadline with a shared cancel flag. Long
// loops poll `ShouldStop()` every few hundred iterations; it is cheap (one
// relaxed atomic load plus a clock read).
//
//   StopToken token = StopToken::WithTimeout(absl::Milliseconds(150));
//   while (!token.ShouldStop()) { ... }
//
// Thread-safety: copies share the cancel flag; all methods are thread-safe.
#ifndef COVPLAN_PLANNER_COMMON_STOP_TOKEN_H_
#define COVPLAN_PLANNER_COMMON_STOP_TOKEN_H_

#include <atomic>
#include <memory>

#include "absl/time/clock.h"
#include "absl/time/time.h"

namespace covplan {

class StopToken {
 public:
  // Never stops unless Cancel() is called.
  StopToken() : flag_(std::make_shared<std::atomic<bool>>(false)) {}

  static StopToken WithDeadline(absl::Time deadline) {
    StopToken t;
    t.deadline_ = deadline;
    return t;
  }
  static StopToken WithTimeout(absl::Duration timeout) {
    return WithDeadline(absl::Now() + timeout);
  }

  // A token that stops when this one does, or at `deadline`, whichever is first.
  StopToken WithEarlierDeadline(absl::Time deadline) const {
    StopToken t = *this;
    if (deadline < t.deadline_) t.deadline_ = deadline;
    return t;
  }

  void Cancel() const { flag_->store(true, std::memory_order_relaxed); }
  bool cancelled() const { return flag_->load(std::memory_order_relaxed); }
  absl::Time deadline() const { return deadline_; }
  bool has_deadline() const { return deadline_ != absl::InfiniteFuture(); }
  absl::Duration remaining() const { return deadline_ - absl::Now(); }

  bool ShouldStop() const {
    if (cancelled()) return true;
    return has_deadline() && absl::Now() >= deadline_;
  }

 private:
  std::shared_ptr<std::atomic<bool>> flag_;
  absl::Time deadline_ = absl::InfiniteFuture();
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_COMMON_STOP_TOKEN_H_
