#include "server/plan_registry.h"

#include <utility>
#include <vector>

namespace covplan {

void PlanRegistry::Put(std::shared_ptr<const RetainedPlan> plan, absl::Time now) {
  if (max_plans_ == 0 || ttl_ <= absl::ZeroDuration()) return;
  std::vector<std::shared_ptr<const RetainedPlan>> dropped;  // freed after the lock is released
  absl::MutexLock lock(&mu_);
  Expire(now, &dropped);
  const std::string id = plan->plan_id;
  if (plans_.count(id) != 0) return;
  order_.push_back(Entry{id, now + ttl_});
  plans_.emplace(id, std::move(plan));
  while (plans_.size() > max_plans_) {
    Drop(order_.front().plan_id, &dropped);
    order_.pop_front();
  }
}

std::shared_ptr<const RetainedPlan> PlanRegistry::Get(const std::string& plan_id, absl::Time now) {
  std::vector<std::shared_ptr<const RetainedPlan>> dropped;  // freed after the lock is released
  absl::MutexLock lock(&mu_);
  Expire(now, &dropped);
  auto it = plans_.find(plan_id);
  return it == plans_.end() ? nullptr : it->second;
}

size_t PlanRegistry::size() const {
  absl::MutexLock lock(&mu_);
  return plans_.size();
}

void PlanRegistry::Expire(absl::Time now,
                          std::vector<std::shared_ptr<const RetainedPlan>>* dropped) {
  while (!order_.empty() && order_.front().expires <= now) {
    Drop(order_.front().plan_id, dropped);
    order_.pop_front();
  }
}

void PlanRegistry::Drop(const std::string& plan_id,
                        std::vector<std::shared_ptr<const RetainedPlan>>* dropped) {
  auto it = plans_.find(plan_id);
  if (it == plans_.end()) return;
  dropped->push_back(std::move(it->second));
  plans_.erase(it);
}

}  // namespace covplan
