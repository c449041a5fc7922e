// Keeps recent plans addressable by plan_id for a limited time, as planner
// types (RetainedPlan: the plan, its request and the coverage area it was
// planned on), so GetPlan and a later Replan continue from them without
// re-parsing protos. Bounded both by age (ttl) and by count, oldest dropped
// first.
//
// An alias is a second id for a retained plan's content (a repeated Plan
// call answered from memory is its own mission under its own id): it names
// the original by id, and its own copy (with its own plan_id) is made when
// the alias is first looked up while the original is retained (otherwise
// the caller rebuilds the original, OriginalOf). An alias costs two ids
// until then; aliases expire as plans do and are bounded by count apart
// from the plans (64 per retained plan), so they never push plans out.
//
//   PlanRegistry plans(absl::Minutes(10), /*max_plans=*/1000);
//   plans.Put(retained);                       // keyed by retained->plan_id
//   plans.PutAlias("p-...", retained->plan_id);  // the same plan, another id
//   std::shared_ptr<const RetainedPlan> p = plans.Get(id);  // null once expired
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_PLAN_REGISTRY_H_
#define COVPLAN_SERVER_PLAN_REGISTRY_H_

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "planner/engine/engine.h"

namespace covplan {

class PlanRegistry {
 public:
  PlanRegistry(absl::Duration ttl, size_t max_plans)
      : ttl_(ttl), max_plans_(max_plans), max_aliases_(64 * max_plans) {}

  void Put(std::shared_ptr<const RetainedPlan> plan, absl::Time now = absl::Now());
  // `alias_id` names `original_id`'s content from now on (an id in use is
  // left alone).
  void PutAlias(const std::string& alias_id, const std::string& original_id,
                absl::Time now = absl::Now());
  // The plan, or null once it expired (or an alias whose original is no
  // longer retained). An alias's first look-up makes its copy, retains it
  // as a plan and sets `*made_from` (if given) to the original's id (else
  // it is cleared).
  std::shared_ptr<const RetainedPlan> Get(const std::string& plan_id, absl::Time now = absl::Now(),
                                          std::string* made_from = nullptr);
  // The original a live alias names; nullopt for other ids.
  std::optional<std::string> OriginalOf(const std::string& alias_id, absl::Time now = absl::Now());
  // Marks an alias used (its copy was made elsewhere).
  void MarkUsed(const std::string& alias_id);
  // The live aliases never used, as (alias, original).
  std::vector<std::pair<std::string, std::string>> UnusedAliases(absl::Time now = absl::Now());
  // Retained plans (aliases not counted).
  size_t size() const;
  size_t aliases() const;

 private:
  using Dropped = std::vector<std::shared_ptr<const RetainedPlan>>;
  struct Entry {
    std::string plan_id;
    absl::Time expires;
  };
  struct Alias {
    std::string original;
    bool used = false;
  };

  // Each moves what it removes into `*dropped`, for the caller to free
  // after releasing mu_ (a large plan takes a while to free).
  void Insert(std::shared_ptr<const RetainedPlan> plan, absl::Time now, Dropped* dropped)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void Expire(absl::Time now, Dropped* dropped) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void Drop(const std::string& plan_id, Dropped* dropped) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  const absl::Duration ttl_;
  const size_t max_plans_;
  const size_t max_aliases_;
  mutable absl::Mutex mu_;
  std::deque<Entry> order_ ABSL_GUARDED_BY(mu_);  // oldest first
  std::unordered_map<std::string, std::shared_ptr<const RetainedPlan>> plans_ ABSL_GUARDED_BY(mu_);
  std::deque<Entry> alias_order_ ABSL_GUARDED_BY(mu_);  // oldest first, one per alias
  std::unordered_map<std::string, Alias> aliases_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PLAN_REGISTRY_H_
