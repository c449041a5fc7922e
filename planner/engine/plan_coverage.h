// One call from a decoded map to a plan (OARP unless `planner` names another
// registered planner), on the engine: for tests, benchmarks and small tools
// that hold an OccupancyMap and want a plan. With `battery` the engine splits
// the plan into charge cycles (planner/energy), whatever the planner.
//
//   PlanOptions o; o.robot.tool_width_m = 0.8; o.no_go = {...};
//   ASSIGN_OR_RETURN(CoveragePlan plan, PlanCoverage(map, o));
//
// Pass a cache to reuse per-map artifacts across calls (same `map_id`).
// Thread-safety: reentrant; thread-safe when the cache is.
#ifndef COVPLAN_PLANNER_ENGINE_PLAN_COVERAGE_H_
#define COVPLAN_PLANNER_ENGINE_PLAN_COVERAGE_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/engine/engine.h"
#include "planner/oarp/oarp_planner.h"

namespace covplan {

struct PlanOptions {
  std::string planner =
      PlannerRegistry::kDefault;  // a registered name; OARP fields apply to "oarp"
  RobotModel robot;
  PartitionSolver partition_solver = PartitionSolver::kPushRelabel;
  TourSolver tour_solver = TourSolver::kGtsp;
  double min_free_fraction = 0.5;
  double time_limit_s = 1.0;
  GtspEffort tour_effort = GtspEffort::kDefault;
  uint64_t seed = 1;
  int num_threads = 1;
  StopToken stop;
  std::vector<PolygonInput> regions;
  std::vector<PolygonInput> no_go;
  std::optional<BatteryOptions> battery;  // a battery-constrained tour (PlanRequest::battery)

  PlanRequest ToRequest() const;
};

absl::StatusOr<EngineResult> PlanCoverageWithArea(const OccupancyMap& map,
                                                  const PlanOptions& options,
                                                  ArtifactCache* cache = nullptr,
                                                  const std::string& map_id = "local",
                                                  EngineLimits limits = {});
absl::StatusOr<CoveragePlan> PlanCoverage(const OccupancyMap& map, const PlanOptions& options,
                                          ArtifactCache* cache = nullptr,
                                          const std::string& map_id = "local",
                                          EngineLimits limits = {});

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_PLAN_COVERAGE_H_
