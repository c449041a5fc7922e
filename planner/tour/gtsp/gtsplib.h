// Reader for GTSPLIB instance files: TSPLIB syntax plus `GTSP_SETS : m` and a
// `GTSP_SET_SECTION` (lines `set_id v1 v2 ... -1`, 1-based vertices).
// Supported EDGE_WEIGHT_TYPEs: EUC_2D, CEIL_2D, ATT, GEO, EXPLICIT (FULL_MATRIX,
// UPPER_ROW, LOWER_ROW, UPPER_DIAG_ROW, LOWER_DIAG_ROW). Costs are the TSPLIB
// integer distances, stored as doubles.
//
//   absl::StatusOr<GtspInstance> inst = ParseGtspLib(text);
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_GTSPLIB_H_
#define COVPLAN_PLANNER_TOUR_GTSP_GTSPLIB_H_

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "planner/tour/gtsp/gtsp.h"

namespace covplan {

struct GtspLibFile {
  std::string name;
  GtspInstance instance;
};

absl::StatusOr<GtspLibFile> ParseGtspLib(std::string_view text);
absl::StatusOr<GtspLibFile> LoadGtspLibFile(const std::string& path);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_GTSP_GTSPLIB_H_
