// The one edge between the covplan.v1 protos and the planner's types, linked
// by the server and the CLI alike (so --local and the server cannot differ).
//
// Conversion maps proto fields onto the engine's request; range checks that
// only need the message happen here with the proto field path in the
// message, everything that needs the map (tool vs pixel size, zones vs map,
// regions with no free cell) happens in the engine, whose messages name the
// same fields. Bad input is InvalidArgument either way.
//
//   EngineLimits limits;  // planner/engine/limits.h
//   ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(request.map(), limits));
//   ASSIGN_OR_RETURN(PlanRequest req, PlanRequestFromProto(request));
//   ... engine.Plan(source, req) ...
//   v1::PlanResponse response;
//   PlanToProto(plan, &response);
//
// Thread-safety: stateless free functions, safe to call concurrently.
#ifndef COVPLAN_API_CONVERT_H_
#define COVPLAN_API_CONVERT_H_

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/engine/engine.h"
#include "planner/engine/site.h"
#include "planner/geometry/area.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/replan/replanner.h"
#include "planner/tour/gtsp/gtsp.h"

namespace covplan {

// Content-derived id: lowercase hex SHA-256 of a canonical encoding of the
// image bytes, YAML text and explicitly set overrides, or of the polygon
// coordinates (64 characters).
std::string ComputeMapId(const v1::Map& map);

// InvalidArgument unless `map_id` looks like an id ComputeMapId produces
// (so it is also safe as a file name).
absl::Status ValidateMapId(absl::string_view map_id);

// Decodes and validates a map (image format, YAML, resolution, thresholds,
// size limits, at least one free pixel).
absl::StatusOr<OccupancyMap> MapFromProto(const v1::Map& map, const EngineLimits& limits);

// A raster or polygon map as the engine's SiteMap (polygons validated with
// their field path, e.g. "map.polygons[2].outer").
absl::StatusOr<SiteMap> SiteFromProto(const v1::Map& map, const EngineLimits& limits);

// What `covplan plan --local` sets beyond the proto (the wire format
// carries none of it), converted here like every other planner option.
struct LocalPlanOptions {
  std::optional<GtspEffort> oarp_tour_effort;  // OARP's tour search effort
};

// The engine request for a PlanRequest: planner, common options, the
// planner's own options (oneof), regions and no-go zones. A request without
// a time limit gets CommonOptions::kDefaultTimeLimitS.
absl::StatusOr<PlanRequest> PlanRequestFromProto(const v1::PlanRequest& request,
                                                 const LocalPlanOptions& local = {});

void PolygonsToProto(const std::vector<PolygonInput>& polygons,
                     google::protobuf::RepeatedPtrField<v1::Polygon>* out);
std::vector<PolygonInput> PolygonsFromProto(
    const google::protobuf::RepeatedPtrField<v1::Polygon>& polygons);

// Fills everything but plan_id, map_id, the zones and the waypoints' times.
void PlanToProto(const CoveragePlan& plan, v1::PlanResponse* out);
// What only the retained plan knows, over what PlanToProto wrote of its plan:
// plan_id, map_id, the request's zones, and each waypoint's time_s on the
// request's robot model.
void RetainedPlanFieldsToProto(const RetainedPlan& plan, v1::PlanResponse* out);
// Everything: PlanToProto, then RetainedPlanFieldsToProto.
void RetainedPlanToProto(const RetainedPlan& plan, v1::PlanResponse* out);

// The inverse (e.g. to render a server's answer as SVG). InvalidArgument on
// an inconsistent response.
absl::StatusOr<CoveragePlan> PlanFromProto(const v1::PlanResponse& response);

// A plan's termination and back (also a fleet plan's, convert_fleet.h).
void TerminationToProto(const Termination& termination, v1::Termination* out);
Termination TerminationFromProto(const v1::Termination& termination);

// Replanning (convert_replan.cc). Range checks of progress and obstacles
// happen in the replanner, with the same field names.
absl::StatusOr<ReplanMethod> ReplanMethodFromProto(v1::ReplanMethod method);
absl::StatusOr<RobotProgress> ProgressFromProto(const v1::RobotProgress& progress);
// The inverses, for a client that sends a replan and reads its statistics.
v1::ReplanMethod ReplanMethodToProto(ReplanMethod method);
void ProgressToProto(const RobotProgress& progress, v1::RobotProgress* out);
ReplanStats ReplanStatsFromProto(const v1::ReplanStats& stats);
Observations ObstaclesFromProto(const v1::Obstacles& obstacles);
// `retained` is the new plan as the server keeps it (plan_id set).
void ReplanToProto(const ReplanResult& result, const RetainedPlan& retained,
                   v1::ReplanResponse* out);
// A plan the server did not retain, rebuilt on the map it was planned on.
absl::StatusOr<RetainedPlan> RetainedPlanFromInline(const v1::InlinePlan& plan,
                                                    const PlanningEngine& engine,
                                                    const MapSource& source, const StopToken& stop);

// Canonical protobuf JSON, snake_case field names, primitive fields always
// printed, indented. This is the CLI's plan.json.
absl::StatusOr<std::string> PlanToJson(const v1::PlanResponse& response);
// Any message in protobuf's JSON mapping as PlanToJson prints a plan (field
// names as in the proto, defaults printed), e.g. a PlanFleetResponse.
absl::StatusOr<std::string> ProtoToJson(const google::protobuf::Message& message);

v1::MapInfo MapInfoFor(const OccupancyMap& map, const std::string& map_id);
v1::MapInfo MapInfoFor(const SiteMap& site, const std::string& map_id);

// Builds a Map proto from a file on disk: a map_server YAML (the image it
// names is read relative to the YAML), a bare .pgm / .png, or a .geojson /
// .json polygon map (metres in a local frame). Unset overrides leave the
// YAML's values; a bare image without `resolution` is InvalidArgument.
struct MapFileOverrides {
  std::optional<double> resolution;
  std::optional<bool> negate;
  std::optional<double> occupied_thresh;
  std::optional<double> free_thresh;
};
absl::StatusOr<v1::Map> MapProtoFromFile(const std::string& path, const MapFileOverrides& overrides,
                                         const EngineLimits& limits);

}  // namespace covplan

#endif  // COVPLAN_API_CONVERT_H_
