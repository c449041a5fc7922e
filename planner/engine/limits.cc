#include "planner/engine/limits.h"

namespace covplan {

absl::Status EngineLimits::Validate() const {
  if (max_image_bytes <= 0 || max_map_pixels <= 0 || max_grid_cells <= 0 || max_ranks <= 0 ||
      max_transition_bytes <= 0 || dense_transition_bytes < 0) {
    return absl::InvalidArgumentError("input limits must be positive");
  }
  return absl::OkStatus();
}

}  // namespace covplan
