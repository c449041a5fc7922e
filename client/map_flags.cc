#include "client/map_flags.h"

#include "planner/common/status_macros.h"

namespace covplan {

absl::StatusOr<MapFileOverrides> MapFileOverridesFromFlags(const ParsedArgs& a) {
  MapFileOverrides overrides;
  ASSIGN_OR_RETURN(overrides.resolution, a.GetDouble("resolution"));
  ASSIGN_OR_RETURN(overrides.free_thresh, a.GetDouble("free-thresh"));
  ASSIGN_OR_RETURN(overrides.occupied_thresh, a.GetDouble("occupied-thresh"));
  if (a.Has("negate")) overrides.negate = true;
  return overrides;
}

}  // namespace covplan
