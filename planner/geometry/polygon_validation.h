// Internal to planner/geometry: checks user polygons before they are unioned into an Area, with
// messages that name the offending element ("no_go[1].holes[0]: ...").
//
//   ASSIGN_OR_RETURN(std::vector<BPolygon> polygons, ValidatePolygons(input, "no_go", limits));
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_PLANNER_GEOMETRY_POLYGON_VALIDATION_H_
#define COVPLAN_PLANNER_GEOMETRY_POLYGON_VALIDATION_H_

#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/geometry/area.h"
#include "planner/geometry/area_data.h"

namespace covplan::geometry_internal {

// Checks the vertex limit, then every ring (finite, closed, >= 3 distinct points, non-zero
// area, simple), then every polygon's holes (inside the outer ring, not overlapping each
// other, interior connected). Returns the polygons with corrected orientation.
absl::StatusOr<std::vector<BPolygon>> ValidatePolygons(const std::vector<PolygonInput>& polygons,
                                                       std::string_view field,
                                                       const AreaLimits& limits);

// "(1.5, 2)": %g when that reads back exactly, %.17g otherwise.
std::string FormatPoint(Point2 p);

}  // namespace covplan::geometry_internal

#endif  // COVPLAN_PLANNER_GEOMETRY_POLYGON_VALIDATION_H_
