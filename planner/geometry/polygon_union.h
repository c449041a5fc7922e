// Internal to planner/geometry: the union of validated polygons, as one valid multipolygon.
//
//   ASSIGN_OR_RETURN(BMultiPolygon shape, UnionPolygons(std::move(polygons), "no_go"));
//
// Thread-safety: a stateless function.
#ifndef COVPLAN_PLANNER_GEOMETRY_POLYGON_UNION_H_
#define COVPLAN_PLANNER_GEOMETRY_POLYGON_UNION_H_

#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/geometry/area_data.h"

namespace covplan::geometry_internal {

// Polygons whose bounding boxes are apart are kept as they are; each group of overlapping
// boxes is unioned on its own, in a balanced tree (O(n log n) overlay work for n polygons,
// and Boost's snapping grid, 1e-7 of the inputs' extent, stays that of the group). A group
// whose union Boost cannot compute validly is InvalidArgument when it has features near that
// grid (an edge or a sliver's width under 1e-4 of the extent), otherwise Internal.
absl::StatusOr<BMultiPolygon> UnionPolygons(std::vector<BPolygon> polygons, std::string_view field);

}  // namespace covplan::geometry_internal

#endif  // COVPLAN_PLANNER_GEOMETRY_POLYGON_UNION_H_
