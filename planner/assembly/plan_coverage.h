// One call from a decoded map to a plan (OARP unless `planner` names another
// shipped planner), on the engine over the shipped planners
// (builtin_planners.h): for tests, benchmarks and small tools that hold an
// OccupancyMap and want a plan. A planner's own options reach it as in any
// request (PlanRequest::options). With `battery` the engine splits the plan
// into charge cycles (planner/energy), whatever the planner.
//
//   PlanOptions o; o.robot.tool_width_m = 0.8; o.no_go = {...};
//   auto oarp = std::make_shared<OarpOptions>(); oarp->tour_solver = TourSolver::kGreedy;
//   o.options = oarp;
//   ASSIGN_OR_RETURN(CoveragePlan plan, PlanCoverage(map, o));
//
// Pass a cache to reuse per-map artifacts across calls (same `map_id`).
// Thread-safety: reentrant; thread-safe when the cache is.
#ifndef COVPLAN_PLANNER_ASSEMBLY_PLAN_COVERAGE_H_
#define COVPLAN_PLANNER_ASSEMBLY_PLAN_COVERAGE_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"

namespace covplan {

struct PlanOptions {
  std::string planner = kDefaultPlanner;  // a shipped planner's name
  // That planner's own options (its type: OarpOptions for "oarp"); null: its
  // defaults.
  std::shared_ptr<const PlannerOptions> options;
  RobotModel robot;
  double min_free_fraction = 0.5;
  // Shorter than a request's default (CommonOptions::kDefaultTimeLimitS):
  // tests and tools plan many small maps.
  double time_limit_s = 1.0;
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

#endif  // COVPLAN_PLANNER_ASSEMBLY_PLAN_COVERAGE_H_
