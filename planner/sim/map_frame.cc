#include "planner/sim/map_frame.h"

#include "absl/strings/str_format.h"
#include "planner/engine/engine.h"

namespace covplan::sim_internal {

absl::Status CheckSameFrame(const OccupancyMap& known, const OccupancyMap& truth) {
  if (known.width() != truth.width() || known.height() != truth.height() ||
      known.resolution() != truth.resolution() || known.origin().x != truth.origin().x ||
      known.origin().y != truth.origin().y) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the known and the true map must have the same size, resolution and origin: known %d x %d "
        "px "
        "at %g m/px from (%g, %g), true %d x %d px at %g m/px from (%g, %g)",
        known.width(), known.height(), known.resolution(), known.origin().x, known.origin().y,
        truth.width(), truth.height(), truth.resolution(), truth.origin().x, truth.origin().y));
  }
  return absl::OkStatus();
}

GridOptions PlanGridOptions(const PlanOptions& options) {
  GridOptions go;
  go.cell_size = options.robot.tool_width_m;
  go.min_free_fraction = options.min_free_fraction;
  go.max_cells = EngineLimits().max_grid_cells;
  return go;
}

}  // namespace covplan::sim_internal
