// The frame the known and the true map share (internal to planner/sim): the
// check that the two maps line up pixel for pixel, and the grid options every
// plan of a simulation reads them at (cells of the tool width), so that the
// true grid and the plan's grid have the same cells.
//
//   RETURN_IF_ERROR(CheckSameFrame(known, truth));
//   ASSIGN_OR_RETURN(Grid true_grid, BuildGrid(truth, PlanGridOptions(options.plan)));
//
// Thread-safety: plain functions.
#ifndef COVPLAN_PLANNER_SIM_MAP_FRAME_H_
#define COVPLAN_PLANNER_SIM_MAP_FRAME_H_

#include "absl/status/status.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"

namespace covplan::sim_internal {

// InvalidArgument, with both maps' figures, unless they have the same size,
// resolution and origin.
absl::Status CheckSameFrame(const OccupancyMap& known, const OccupancyMap& truth);

// The grid of the plans made with `options`.
GridOptions PlanGridOptions(const PlanOptions& options);

}  // namespace covplan::sim_internal

#endif  // COVPLAN_PLANNER_SIM_MAP_FRAME_H_
