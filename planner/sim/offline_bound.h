// The offline references a simulated run is compared with (thesis §4.6): the
// plan of the true map, as if the robot had known it from the start
// (OfflineLowerBound), and the true map at the level of cells
// (CellLevelTruth), whose plan is the bound of the cell model the replanner
// and the simulated robot work in.
//
//   ASSIGN_OR_RETURN(OfflineBound lb, OfflineLowerBound(truth, options.plan));
//   ASSIGN_OR_RETURN(OccupancyMap cells, CellLevelTruth(known, truth, options.plan));
//   ASSIGN_OR_RETURN(OfflineBound cell_bound, OfflineLowerBound(cells, options.plan));
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_SIM_OFFLINE_BOUND_H_
#define COVPLAN_PLANNER_SIM_OFFLINE_BOUND_H_

#include <cstdint>

#include "absl/status/statusor.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

// The offline lower bound of the evaluation: the plan (options.planner, with
// options.battery when given) of the true map, as if the robot had known it
// from the start.
struct OfflineBound {
  double duration_s = 0.0;  // the plan's estimated duration
  double covered_free_area_ratio = 0.0;
  double swept_reachable_ratio = 0.0;  // the plan's own, on the true map
  int64_t num_ranks = 0;
  // Battery plans: the offline plan's charge cycles (duration_s has no
  // recharge time in it; add recharge_s for each).
  int charge_cycles = 0;
};
absl::StatusOr<OfflineBound> OfflineLowerBound(const OccupancyMap& truth,
                                               const PlanOptions& options);

// The true map as the simulation sees it: `known` with every cell that is
// free on the known grid but blocked on the true grid filled (grid of
// options.robot.tool_width_m). OfflineLowerBound of this map is the bound of
// the cell model the replanner works in (new thin obstacles ignored, as the
// simulated robot ignores them). InvalidArgument as Simulate for maps that
// do not match.
absl::StatusOr<OccupancyMap> CellLevelTruth(const OccupancyMap& known, const OccupancyMap& truth,
                                            const PlanOptions& options);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_SIM_OFFLINE_BOUND_H_
