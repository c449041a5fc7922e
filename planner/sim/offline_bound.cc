#include "planner/sim/offline_bound.h"

#include <cmath>

#include "planner/common/status_macros.h"
#include "planner/grid/grid.h"
#include "planner/sim/map_frame.h"

namespace covplan {

absl::StatusOr<OfflineBound> OfflineLowerBound(const OccupancyMap& truth,
                                               const PlanOptions& options) {
  ASSIGN_OR_RETURN(CoveragePlan plan, PlanCoverage(truth, options));
  OfflineBound b;
  b.duration_s = plan.stats.estimated_duration_s;
  b.covered_free_area_ratio = plan.stats.covered_free_area_ratio;
  b.swept_reachable_ratio = plan.stats.swept_reachable_ratio;
  b.num_ranks = plan.stats.num_ranks;
  b.charge_cycles = static_cast<int>(plan.cycles.size());
  return b;
}

absl::StatusOr<OccupancyMap> CellLevelTruth(const OccupancyMap& known, const OccupancyMap& truth,
                                            const PlanOptions& options) {
  RETURN_IF_ERROR(sim_internal::CheckSameFrame(known, truth));
  const GridOptions go = sim_internal::PlanGridOptions(options);
  ASSIGN_OR_RETURN(Grid known_grid, BuildGrid(known, go));
  ASSIGN_OR_RETURN(GridFrame frame, PlanGridFrame(truth, go));
  ASSIGN_OR_RETURN(Grid true_grid,
                   BuildGridFromFractions(truth, go, frame, CellFreeFractions(truth, frame)));
  OccupancyMap out = known;
  for (int r = 0; r < known.height(); ++r) {
    for (int c = 0; c < known.width(); ++c) {
      const int row = static_cast<int>(std::floor((r + 0.5) / frame.px_per_cell));
      const int col = static_cast<int>(std::floor((c + 0.5) / frame.px_per_cell));
      if (known_grid.IsFree(row, col) && !true_grid.IsFree(row, col))
        out.set(r, c, CellState::kOccupied);
    }
  }
  return out;
}

}  // namespace covplan
