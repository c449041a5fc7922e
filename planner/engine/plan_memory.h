// Remembered plans: the engine keeps the best plan found
// per request, in the same ArtifactCache (and byte budget) as the per-map
// artifacts, so the server and `covplan plan --local` share the behaviour.
//
// Two entries per request, both derived from the request's CoverageArea key
// (so they start with "<map content id>/" and a map's prefix erase drops
// them; the map id is a content id, so a key can never name other content):
//
//   ...|area(zones)|plan(planner, options, robot speeds, battery)|tour()
//       RememberedTour: the last tour found for these inputs, from any start
//       pose or seed; a request that differs only there warm-starts from it.
//   ...|area(zones)|plan(...)|exact(seed, threads, start, end)
//       RememberedPlan: the answer to exactly this request (the time budget
//       aside); an identical request gets it without search ("cache_hit"),
//       or, with improve_remembered, searches on from it ("improved"). A
//       search that converged by itself gives the same answer with any
//       budget (the seed fixes it), so it answers every budget; one its own
//       time limit stopped answers only requests with no more time, and a
//       request with more searches on from it ("improved"). Plans the
//       caller's deadline cut short are not remembered (their tour is).
//
// Tool width and min_free_fraction are in the grid key, zones in the area
// key. The seed and thread count are in the exact key only: a request with
// another seed would, cold, search another way and may find another tour, so
// it is not answered with this one; it warm-starts instead ("warm_start").
//
//   PlanMemoryKeys keys = PlanMemoryKeysFor(ctx.area_key, "oarp", *options, request.common,
//                                           request.battery);
//   std::shared_ptr<const RememberedPlan> hit = FindRemembered<RememberedPlan>(cache, keys.exact);
//   if (hit != nullptr && hit->Answers(request.common.time_limit_s)) { ... hit->plan ... }
//
// Thread-safety: entries are immutable once put; the cache locks.
#ifndef COVPLAN_PLANNER_ENGINE_PLAN_MEMORY_H_
#define COVPLAN_PLANNER_ENGINE_PLAN_MEMORY_H_

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "planner/energy/battery.h"
#include "planner/engine/artifact_cache.h"
#include "planner/engine/planner.h"
#include "planner/engine/site.h"
#include "planner/plan/coverage_plan.h"

namespace covplan {

// The answer to one request, as the engine returned it (statistics filled),
// without its grid (the coverage area holds it; a hit re-attaches it).
class RememberedPlan final : public Artifact {
 public:
  CoveragePlan plan;
  int generation = 0;  // improve_remembered runs that searched on from it
  // The largest time_limit_s searched for it. A search its time limit
  // stopped (termination kTime) answers only requests with no more time.
  double time_limit_s = 0.0;
  // True when it answers an identical request with `time_limit_s` at once.
  bool Answers(double request_time_limit_s) const {
    return plan.termination.limit != TerminationLimit::kTime ||
           request_time_limit_s <= time_limit_s;
  }
  size_t MemoryBytes() const override { return sizeof(*this) - sizeof(plan) + plan.MemoryBytes(); }
};

// A tour to warm-start from: TourModel vertices in visiting order.
class RememberedTour final : public Artifact {
 public:
  std::vector<int> vertices;
  size_t MemoryBytes() const override { return sizeof(*this) + vertices.capacity() * sizeof(int); }
};

struct PlanMemoryKeys {
  std::string tour;   // RememberedTour
  std::string exact;  // RememberedPlan
};

// Keys of a request planned on `area_key`. `common.robot.start/end` must
// already hold the effective poses (a battery tour's station).
PlanMemoryKeys PlanMemoryKeysFor(const ArtifactKey<CoverageArea>& area_key,
                                 std::string_view planner, const PlannerOptions& options,
                                 const CommonOptions& common,
                                 const std::optional<BatteryOptions>& battery);

template <typename T>
std::shared_ptr<const T> FindRemembered(ArtifactCache& cache, const std::string& key) {
  return std::dynamic_pointer_cast<const T>(cache.Find(key));
}

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_PLAN_MEMORY_H_
