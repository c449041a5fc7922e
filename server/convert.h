// The one edge between the covplan.v1 protos and the planner's types.
//
// Every request field is validated here, so the server and the CLI's --local
// mode reject the same inputs with the same messages: bad input is
// InvalidArgument with a message saying which field is wrong and why.
//
//   InputLimits limits;
//   ASSIGN_OR_RETURN(OccupancyMap map, MapFromProto(request.map(), limits));
//   ASSIGN_OR_RETURN(PlanOptions options, PlanOptionsFromProto(request));
//   RETURN_IF_ERROR(ValidatePlanForMap(options, map, limits));
//   ... plan ...
//   v1::PlanResponse response;
//   PlanToProto(plan, &response);
//
// Thread-safety: stateless free functions, safe to call concurrently.
#ifndef COVPLAN_SERVER_CONVERT_H_
#define COVPLAN_SERVER_CONVERT_H_

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/coverage_planner.h"

namespace covplan {

// Size limits on untrusted input.
struct InputLimits {
  int64_t max_image_bytes = 64ll << 20;   // encoded image size
  int64_t max_map_pixels = 64'000'000;    // decoded width * height
  int64_t max_grid_cells = 4'000'000;     // tool-width cells
  int64_t max_ranks = 1000;               // coverage ranks (transition table ~ ranks^2)

  absl::Status Validate() const;
};

// Content-derived id: lowercase hex SHA-256 of a canonical encoding of the
// image bytes, YAML text and explicitly set overrides (64 characters).
std::string ComputeMapId(const v1::Map& map);

// InvalidArgument unless `map_id` looks like an id ComputeMapId produces
// (so it is also safe as a file name).
absl::Status ValidateMapId(absl::string_view map_id);

// Decodes and validates a map (image format, YAML, resolution, thresholds,
// size limits, at least one free pixel).
absl::StatusOr<OccupancyMap> MapFromProto(const v1::Map& map, const InputLimits& limits);

// Validates the robot model, solvers, budget and grid parameters.
absl::StatusOr<PlanOptions> PlanOptionsFromProto(const v1::PlanRequest& request);

// The decomposition options for `options`, with the grid cell limit applied.
DecompositionOptions DecompositionOptionsFor(const PlanOptions& options,
                                             const InputLimits& limits);

// Checks that need both the options and the decoded map: the tool must be at
// least one pixel wide and no wider than the map, and the grid must stay
// within limits.max_grid_cells.
absl::Status ValidatePlanForMap(const PlanOptions& options, const OccupancyMap& map,
                                const InputLimits& limits);

// Fills everything but plan_id and map_id.
void PlanToProto(const CoveragePlan& plan, v1::PlanResponse* out);

// The inverse (e.g. to render a server's answer as SVG). InvalidArgument on
// an inconsistent response.
absl::StatusOr<CoveragePlan> PlanFromProto(const v1::PlanResponse& response);

// Canonical protobuf JSON, snake_case field names, primitive fields always
// printed, indented. This is the CLI's plan.json.
absl::StatusOr<std::string> PlanToJson(const v1::PlanResponse& response);

v1::MapInfo MapInfoFor(const OccupancyMap& map, const std::string& map_id);

// Builds a Map proto from a file on disk: a map_server YAML (the image it
// names is read relative to the YAML) or a bare .pgm / .png. Unset overrides
// leave the YAML's values; a bare image needs `resolution`.
struct MapFileOverrides {
  std::optional<double> resolution;
  std::optional<bool> negate;
  std::optional<double> occupied_thresh;
  std::optional<double> free_thresh;
};
absl::StatusOr<v1::Map> MapProtoFromFile(const std::string& path,
                                         const MapFileOverrides& overrides,
                                         const InputLimits& limits);

}  // namespace covplan

#endif  // COVPLAN_SERVER_CONVERT_H_
