#include "server/plan_registry.h"

#include <utility>
#include <vector>

namespace covplan {

void PlanRegistry::Put(std::shared_ptr<const RetainedPlan> plan, absl::Time now) {
  if (max_plans_ == 0 || ttl_ <= absl::ZeroDuration()) return;
  Dropped dropped;  // freed after the lock is released
  absl::MutexLock lock(&mu_);
  Expire(now, &dropped);
  Insert(std::move(plan), now, &dropped);
}

void PlanRegistry::PutAlias(const std::string& alias_id, const std::string& original_id,
                            absl::Time now) {
  if (max_plans_ == 0 || ttl_ <= absl::ZeroDuration()) return;
  Dropped dropped;
  absl::MutexLock lock(&mu_);
  Expire(now, &dropped);
  if (plans_.count(alias_id) != 0 || aliases_.count(alias_id) != 0) return;
  alias_order_.push_back(Entry{alias_id, now + ttl_});
  aliases_.emplace(alias_id, Alias{original_id, false});
  while (aliases_.size() > max_aliases_) {
    aliases_.erase(alias_order_.front().plan_id);
    alias_order_.pop_front();
  }
}

std::shared_ptr<const RetainedPlan> PlanRegistry::Get(const std::string& plan_id, absl::Time now,
                                                      std::string* made_from) {
  if (made_from != nullptr) made_from->clear();
  Dropped dropped;
  std::shared_ptr<const RetainedPlan> original;
  {
    absl::MutexLock lock(&mu_);
    Expire(now, &dropped);
    if (auto it = plans_.find(plan_id); it != plans_.end()) return it->second;
    auto alias = aliases_.find(plan_id);
    if (alias == aliases_.end()) return nullptr;
    auto it = plans_.find(alias->second.original);
    if (it == plans_.end()) return nullptr;  // the caller rebuilds it (OriginalOf)
    original = it->second;
  }
  // The alias's own copy, made outside the lock (a plan is large).
  auto copy = std::make_shared<RetainedPlan>(*original);
  copy->plan_id = plan_id;
  absl::MutexLock lock(&mu_);
  // Another look-up may have made it first: one copy is retained.
  if (auto it = plans_.find(plan_id); it != plans_.end()) return it->second;
  auto alias = aliases_.find(plan_id);
  if (alias == aliases_.end()) return nullptr;  // expired meanwhile
  alias->second.used = true;
  Insert(copy, now, &dropped);
  if (made_from != nullptr) *made_from = original->plan_id;
  return copy;
}

std::optional<std::string> PlanRegistry::OriginalOf(const std::string& alias_id, absl::Time now) {
  Dropped dropped;
  absl::MutexLock lock(&mu_);
  Expire(now, &dropped);
  auto alias = aliases_.find(alias_id);
  if (alias == aliases_.end()) return std::nullopt;
  return alias->second.original;
}

void PlanRegistry::MarkUsed(const std::string& alias_id) {
  absl::MutexLock lock(&mu_);
  if (auto alias = aliases_.find(alias_id); alias != aliases_.end()) alias->second.used = true;
}

std::vector<std::pair<std::string, std::string>> PlanRegistry::UnusedAliases(absl::Time now) {
  Dropped dropped;
  std::vector<std::pair<std::string, std::string>> unused;
  absl::MutexLock lock(&mu_);
  Expire(now, &dropped);
  for (const Entry& e : alias_order_) {
    const Alias& alias = aliases_.at(e.plan_id);
    if (!alias.used) unused.emplace_back(e.plan_id, alias.original);
  }
  return unused;
}

size_t PlanRegistry::size() const {
  absl::MutexLock lock(&mu_);
  return plans_.size();
}

size_t PlanRegistry::aliases() const {
  absl::MutexLock lock(&mu_);
  return aliases_.size();
}

void PlanRegistry::Insert(std::shared_ptr<const RetainedPlan> plan, absl::Time now,
                          Dropped* dropped) {
  const std::string id = plan->plan_id;
  if (plans_.count(id) != 0) return;
  order_.push_back(Entry{id, now + ttl_});
  plans_.emplace(id, std::move(plan));
  while (plans_.size() > max_plans_) {
    Drop(order_.front().plan_id, dropped);
    order_.pop_front();
  }
}

void PlanRegistry::Expire(absl::Time now, Dropped* dropped) {
  while (!order_.empty() && order_.front().expires <= now) {
    Drop(order_.front().plan_id, dropped);
    order_.pop_front();
  }
  while (!alias_order_.empty() && alias_order_.front().expires <= now) {
    aliases_.erase(alias_order_.front().plan_id);
    alias_order_.pop_front();
  }
}

void PlanRegistry::Drop(const std::string& plan_id, Dropped* dropped) {
  auto it = plans_.find(plan_id);
  if (it == plans_.end()) return;
  dropped->push_back(std::move(it->second));
  plans_.erase(it);
}

}  // namespace covplan
