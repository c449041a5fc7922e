#include "server/service_options.h"

#include <algorithm>

namespace covplan {

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
  if (replica.size() > 32 || !std::all_of(replica.begin(), replica.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
      })) {
    return absl::InvalidArgumentError("replica must be at most 32 of [a-z0-9_]");
  }
  if (max_live_streams < 0) return absl::InvalidArgumentError("max_live_streams must be >= 0");
  if (session_idle <= absl::ZeroDuration())
    return absl::InvalidArgumentError("session_idle must be > 0");
  return absl::OkStatus();
}

}  // namespace covplan
