#include "server/plan_registry.h"

#include <utility>

namespace covplan {

void PlanRegistry::Put(std::shared_ptr<const RetainedPlan> plan, absl::Time now) {
  if (max_plans_ == 0 || ttl_ <= absl::ZeroDuration()) return;
  absl::MutexLock lock(&mu_);
  Expire(now);
  const std::string id = plan->plan_id;
  if (plans_.count(id) != 0) return;
  order_.push_back(Entry{id, now + ttl_});
  plans_.emplace(id, std::move(plan));
  while (plans_.size() > max_plans_) {
    plans_.erase(order_.front().plan_id);
    order_.pop_front();
  }
}

std::shared_ptr<const RetainedPlan> PlanRegistry::Get(const std::string& plan_id,
                                                          absl::Time now) {
  absl::MutexLock lock(&mu_);
  Expire(now);
  auto it = plans_.find(plan_id);
  return it == plans_.end() ? nullptr : it->second;
}

size_t PlanRegistry::size() const {
  absl::MutexLock lock(&mu_);
  return plans_.size();
}

void PlanRegistry::Expire(absl::Time now) {
  while (!order_.empty() && order_.front().expires <= now) {
    plans_.erase(order_.front().plan_id);
    order_.pop_front();
  }
}

}  // namespace covplan
