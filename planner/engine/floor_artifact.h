// The reachable floor of a coverage area (planner/plan/floor_measure.h) as a
// cached artifact, and the plan statistics measured against it: built once
// per area (keyed under the area's key), then each plan only stamps its path.
//
//   RETURN_IF_ERROR(MeasurePlanFloor(ctx, &plan));  // plan.stats.reachable_area_m2 ...
//
// Thread-safety: reentrant; the artifact is immutable.
#ifndef COVPLAN_PLANNER_ENGINE_FLOOR_ARTIFACT_H_
#define COVPLAN_PLANNER_ENGINE_FLOOR_ARTIFACT_H_

#include <cstddef>
#include <memory>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/engine/artifact_cache.h"
#include "planner/engine/planner.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/floor_measure.h"

namespace covplan {

class FloorArtifact final : public Artifact {
 public:
  FloorReach reach;
  size_t MemoryBytes() const override { return sizeof(*this) + reach.reachable.capacity(); }
};

// ctx's area's reachable floor: from the cache, or built and cached.
// PlanningEngine::Prepare calls it so that a warmed area's first plan pays
// only for the stamping.
absl::StatusOr<std::shared_ptr<const FloorArtifact>> FloorFor(const PlanContext& ctx);

// Fills plan->stats' reachable_area_m2, swept_reachable_ratio and
// missed_reachable_m2 for the plan on ctx's area (0 for a map without
// pixels) and floor_ms, the time it took (the floor's build included when
// it was not cached).
absl::Status MeasurePlanFloor(const PlanContext& ctx, CoveragePlan* plan);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_FLOOR_ARTIFACT_H_
