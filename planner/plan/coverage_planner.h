// The planning pipeline: map -> grid -> minimum rank partition -> tour ->
// waypoints. Split in two so a server can cache the per-map part:
//
//   absl::StatusOr<std::shared_ptr<const Decomposition>> d =
//       BuildDecomposition(map, DecompositionKeyOptions{...});
//   absl::StatusOr<CoveragePlan> plan = PlanOnDecomposition(**d, options);
//
// or in one go: PlanCoverage(map, options).
//
// Thread-safety: Decomposition is immutable and may be shared between
// threads; the functions are reentrant.
#ifndef COVPLAN_PLANNER_PLAN_COVERAGE_PLANNER_H_
#define COVPLAN_PLANNER_PLAN_COVERAGE_PLANNER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/partition/partitioner.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/robot_model.h"

namespace covplan {

class TransitionTable;  // planner/tour/transitions.h

enum class TourSolver { kGreedy, kGtsp };

// What determines a decomposition (the cache key, together with the map id).
struct DecompositionOptions {
  GridOptions grid;  // grid.cell_size = tool width
  PartitionSolver partition_solver = PartitionSolver::kMinCut;
  int num_threads = 1;  // for the transition table; not part of the key
  // The all-pairs transition table grows with the square of the rank count
  // (and its build time with ranks x cells): beyond this many ranks the
  // decomposition is refused with InvalidArgument. Not part of the key.
  int64_t max_ranks = 1000;
  absl::Status Validate() const;
  std::string CacheKey() const;  // stable text form of the fields that matter
};

// Per-map, per-tool-width data: built once, immutable, shared.
struct Decomposition {
  std::shared_ptr<const Grid> grid;
  std::shared_ptr<const RankPartition> partition;
  std::shared_ptr<const TransitionTable> transitions;  // may be null until computed
  double map_free_area_m2 = 0.0;
  double covered_free_area_ratio = 0.0;
  // Free cells outside the largest connected free area (not planned).
  int64_t unreachable_free_cells = 0;
  double grid_ms = 0.0;
  double partition_ms = 0.0;
  double transitions_ms = 0.0;
  size_t MemoryBytes() const;
};

struct PlanOptions {
  RobotModel robot;
  PartitionSolver partition_solver = PartitionSolver::kMinCut;
  TourSolver tour_solver = TourSolver::kGtsp;
  double min_free_fraction = 0.5;
  double time_limit_s = 1.0;  // tour search budget (also bounded by `stop`)
  // kFast/kDefault stop by themselves when the search converges (often well
  // within the budget); kThorough keeps improving until the budget is spent.
  GtspEffort tour_effort = GtspEffort::kDefault;
  uint64_t seed = 1;
  int num_threads = 1;
  StopToken stop;             // deadline / cancellation for the whole request

  absl::Status Validate() const;
  DecompositionOptions decomposition() const;
};

absl::StatusOr<std::shared_ptr<const Decomposition>> BuildDecomposition(
    const OccupancyMap& map, const DecompositionOptions& options, const StopToken& stop);

absl::StatusOr<CoveragePlan> PlanOnDecomposition(const Decomposition& decomposition,
                                                 const PlanOptions& options);

// Path length, turns and duration recomputed from waypoints alone (the
// robot turns in place to each waypoint's heading, then drives straight).
PlanStats ComputePathStats(const std::vector<Waypoint>& path, const RobotModel& robot);

absl::StatusOr<CoveragePlan> PlanCoverage(const OccupancyMap& map, const PlanOptions& options);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_COVERAGE_PLANNER_H_
