#include "planner/engine/floor_artifact.h"

#include <memory>

#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/engine/site.h"

namespace covplan {

absl::StatusOr<std::shared_ptr<const FloorArtifact>> FloorFor(const PlanContext& ctx) {
  const CoverageArea& area = *ctx.area;
  bool hit = false;
  return GetOrBuild(
      *ctx.cache, ctx.area_key.Derive<FloorArtifact>("floor", ""), ctx.common->stop,
      [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const FloorArtifact>> {
        auto out = std::make_shared<FloorArtifact>();
        out->reach =
            ComputeFloorReach(*area.drive, area.zones.no_go.get(), area.zones.regions.get());
        return std::shared_ptr<const FloorArtifact>(std::move(out));
      },
      &hit);
}

absl::Status MeasurePlanFloor(const PlanContext& ctx, CoveragePlan* plan) {
  const absl::Time t0 = absl::Now();
  ASSIGN_OR_RETURN(std::shared_ptr<const FloorArtifact> floor, FloorFor(ctx));
  const FloorMeasure m = MeasureFloor(floor->reach, plan->path, /*keep_missed=*/false);
  PlanStats& s = plan->stats;
  s.reachable_area_m2 = m.reachable_area_m2;
  s.swept_reachable_ratio = m.swept_reachable_ratio;
  s.missed_reachable_m2 = m.missed_reachable_m2;
  s.floor_ms = absl::ToDoubleMilliseconds(absl::Now() - t0);
  return absl::OkStatus();
}

}  // namespace covplan
