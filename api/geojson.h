// Reads polygons (regions, no-go zones, polygon maps) from GeoJSON. The structure is RFC 7946,
// but coordinates are taken as a local metric frame: [x, y] in metres; a third coordinate is
// ignored. Accepted: a Polygon, MultiPolygon, GeometryCollection, Feature (whose geometry is one
// of those, or null) or FeatureCollection; every polygon is collected in document order. Any
// other geometry (Point, LineString, ...) is an error naming its JSON path.
//
//   ASSIGN_OR_RETURN(std::vector<PolygonInput> polygons,
//                    ParseGeoJsonPolygons(text, "site.geojson"));
//   ASSIGN_OR_RETURN(Area region, Area::Create(polygons, "site.geojson"));
//
// Rings are passed through unchanged: closure, orientation and validity are Area::Create's job.
// Thread-safety: a stateless function; safe to call concurrently.
#ifndef COVPLAN_API_GEOJSON_H_
#define COVPLAN_API_GEOJSON_H_

#include <cstddef>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/geometry/area.h"

namespace covplan {

// Errors are InvalidArgument and start with `source` and the JSON path, e.g.
//   "site.geojson: features[2].geometry.coordinates[0][5]: expected a position [x, y] of numbers"
//   "site.geojson: not valid JSON: <parser message>"
//   "site.geojson: no Polygon or MultiPolygon found"
// Inputs longer than `max_bytes` are rejected before parsing.
absl::StatusOr<std::vector<PolygonInput>> ParseGeoJsonPolygons(std::string_view json,
                                                               std::string_view source,
                                                               size_t max_bytes = 16u << 20);

}  // namespace covplan

#endif  // COVPLAN_API_GEOJSON_H_
