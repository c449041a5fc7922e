#include "planner/assembly/plan_coverage.h"

#include <memory>
#include <utility>

#include "planner/common/status_macros.h"

namespace covplan {

PlanRequest PlanOptions::ToRequest() const {
  PlanRequest r;
  r.planner = planner;
  r.common.robot = robot;
  r.common.min_free_fraction = min_free_fraction;
  r.common.time_limit_s = time_limit_s;
  r.common.seed = seed;
  r.common.num_threads = num_threads;
  r.common.stop = stop;
  r.options = options;
  r.regions = regions;
  r.no_go = no_go;
  r.battery = battery;
  return r;
}

absl::StatusOr<EngineResult> PlanCoverageWithArea(const OccupancyMap& map,
                                                  const PlanOptions& options, ArtifactCache* cache,
                                                  const std::string& map_id, EngineLimits limits) {
  static const PlannerRegistry* const registry = new PlannerRegistry(BuiltinPlanners());
  LocalArtifactCache local;
  PlanningEngine engine(registry, cache != nullptr ? cache : &local, limits);
  MapSource source;
  source.map_id = map_id;
  source.load = [&map]() -> absl::StatusOr<SiteMap> {
    SiteMap site;
    site.raster = std::shared_ptr<const OccupancyMap>(&map, [](const OccupancyMap*) {});
    return site;
  };
  return engine.Plan(source, options.ToRequest());
}

absl::StatusOr<CoveragePlan> PlanCoverage(const OccupancyMap& map, const PlanOptions& options,
                                          ArtifactCache* cache, const std::string& map_id,
                                          EngineLimits limits) {
  ASSIGN_OR_RETURN(EngineResult result, PlanCoverageWithArea(map, options, cache, map_id, limits));
  return std::move(result.plan);
}

}  // namespace covplan
