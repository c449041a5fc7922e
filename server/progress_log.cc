#include "server/progress_log.h"

#include <vector>

#include "server/log.h"

namespace covplan {

void ProgressLog::Record(const std::string& plan_id, const v1::RobotProgress& progress) {
  if (plan_id.empty() || plan_id.size() > 64) return;
  bool queue = false;
  {
    absl::MutexLock lock(&mu_);
    progress_[plan_id] = {++clock_, progress};
    dirty_.insert(plan_id);
    while (progress_.size() > max_plans_) {
      auto oldest = progress_.begin();
      for (auto it = progress_.begin(); it != progress_.end(); ++it) {
        if (it->second.first < oldest->second.first) oldest = it;
      }
      dirty_.erase(oldest->first);
      progress_.erase(oldest);
    }
    if (!flush_queued_) queue = flush_queued_ = true;
  }
  if (queue && !io_pool_->TrySubmit([this] { Flush(); })) {
    absl::MutexLock lock(&mu_);
    flush_queued_ = false;  // the next report tries again
  }
}

void ProgressLog::Flush() {
  absl::MutexLock in_order(&write_mu_);
  std::vector<std::pair<std::string, std::string>> writes;
  {
    absl::MutexLock lock(&mu_);
    for (const std::string& id : dirty_) {
      auto it = progress_.find(id);
      if (it != progress_.end()) writes.emplace_back(id, it->second.second.SerializeAsString());
    }
    dirty_.clear();
    flush_queued_ = false;
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

std::optional<v1::RobotProgress> ProgressLog::Recorded(const std::string& plan_id) {
  {
    absl::MutexLock lock(&mu_);
    if (auto it = progress_.find(plan_id); it != progress_.end()) return it->second.second;
  }
  absl::StatusOr<std::string> bytes = store_->GetProgress(plan_id);
  v1::RobotProgress progress;
  if (!bytes.ok() || !progress.ParseFromString(*bytes)) return std::nullopt;
  return progress;
}

}  // namespace covplan
