// Keeps recent plans addressable by plan_id for a limited time, as planner
// types (RetainedPlan: the plan, its request and the coverage area it was
// planned on), so GetPlan and a later Replan continue from them without
// re-parsing protos. Bounded both by age (ttl) and by count, oldest dropped
// first.
//
//   PlanRegistry plans(absl::Minutes(10), /*max_plans=*/1000);
//   plans.Put(retained);                       // keyed by retained->plan_id
//   std::shared_ptr<const RetainedPlan> p = plans.Get(id);  // null once expired
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_PLAN_REGISTRY_H_
#define COVPLAN_SERVER_PLAN_REGISTRY_H_

#include <deque>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "planner/engine/engine.h"

namespace covplan {

class PlanRegistry {
 public:
  PlanRegistry(absl::Duration ttl, size_t max_plans) : ttl_(ttl), max_plans_(max_plans) {}

  void Put(std::shared_ptr<const RetainedPlan> plan, absl::Time now = absl::Now());
  std::shared_ptr<const RetainedPlan> Get(const std::string& plan_id, absl::Time now = absl::Now());
  size_t size() const;

 private:
  // Both move what they remove into `*dropped`, for the caller to free
  // after releasing mu_ (a large plan takes a while to free).
  void Expire(absl::Time now, std::vector<std::shared_ptr<const RetainedPlan>>* dropped)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void Drop(const std::string& plan_id, std::vector<std::shared_ptr<const RetainedPlan>>* dropped)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  struct Entry {
    std::string plan_id;
    absl::Time expires;
  };
  const absl::Duration ttl_;
  const size_t max_plans_;
  mutable absl::Mutex mu_;
  std::deque<Entry> order_ ABSL_GUARDED_BY(mu_);  // oldest first
  std::unordered_map<std::string, std::shared_ptr<const RetainedPlan>> plans_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PLAN_REGISTRY_H_
