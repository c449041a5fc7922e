// Polygonal areas in the map frame: operating regions, no-go zones and the free space of a
// polygon map. An Area is the validated, normalised union of input polygons; it answers point,
// segment and box queries exactly (Boost.Geometry underneath) and turns itself into cell
// fractions or an occupancy image for the grid-based planners.
//
//   std::vector<PolygonInput> zones = ...;   // e.g. from ParseGeoJsonPolygons
//   ASSIGN_OR_RETURN(Area no_go, Area::Create(zones, "no_go"));
//   if (no_go.InInterior(p)) ...
//   std::vector<float> f = CellOverlapFractions(no_go, rows, cols, 0.5, origin);
//   ASSIGN_OR_RETURN(OccupancyMap map, RasterizeArea(free_space, 0.05, RasterRule::kInside));
//
// Thread-safety: an Area is immutable; copies share their geometry and every const method and
// the free functions below are safe to call concurrently.
#ifndef COVPLAN_PLANNER_GEOMETRY_AREA_H_
#define COVPLAN_PLANNER_GEOMETRY_AREA_H_

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

namespace geometry_internal {
struct AreaData;
}  // namespace geometry_internal

enum class RasterRule;

// One polygon as given by a user, in map-frame metres. Rings are closed (first point repeated
// at the end, as in GeoJSON and WKT); orientation is free.
struct PolygonInput {
  std::vector<Point2> outer;
  std::vector<std::vector<Point2>> holes;
};

struct AreaLimits {
  int64_t max_vertices = 100000;  // over all rings of one Area, closing points included
  // Largest width or height of all polygons together. Boost.Geometry snaps overlay points to
  // 1/round(1e7 / extent) m: 0.1 m at 1000 km, whole metres from 10,000 km on.
  double max_extent_m = 1e6;
};

class Area {
 public:
  // An empty area.
  Area() = default;

  // Validates and unions `polygons`. `field` names the input in error messages ("regions",
  // "no_go", "map.polygons"); every failure is InvalidArgument naming the element, e.g.
  // "no_go[1].outer: ring is not closed: ..." or "regions[0].outer vertex 4: ...". Rings must
  // be closed, finite, simple (no self-intersection or spike), of non-zero area; holes must lie
  // inside their outer ring and not overlap each other. Different polygons may overlap or
  // touch: they are unioned. An empty vector gives an empty Area. Polygons with features finer
  // than Boost.Geometry can resolve in their extent (see AreaLimits) may be InvalidArgument;
  // Internal if its union fails on anything else (not seen so far).
  static absl::StatusOr<Area> Create(const std::vector<PolygonInput>& polygons,
                                     std::string_view field, const AreaLimits& limits = {});

  bool empty() const;
  double AreaM2() const;
  // Bounding box of the area; (0, 0) when empty.
  Point2 min_corner() const;
  Point2 max_corner() const;
  // Vertices of the normalised rings, closing points not counted.
  int64_t num_vertices() const;

  // True when p lies in the closed area (interior or boundary).
  bool Contains(Point2 p) const;
  // True when p lies strictly inside.
  bool InInterior(Point2 p) const;
  // Length in metres of the part of segment a-b inside the interior. Parts running along the
  // boundary (within ~1e-9 m) and single touching points count 0.
  double SegmentLengthInInterior(Point2 a, Point2 b) const;
  // Area of the intersection with the box [x0, x1] x [y0, y1] (0 for an empty or invalid box).
  double BoxOverlapM2(double x0, double y0, double x1, double y1) const;

  // The normalised geometry as WKT with %.17g numbers; rings start at their lexicographically
  // smallest vertex and polygons and holes are sorted, so equal inputs in any order, rotation
  // or orientation give the same text. For cache keys.
  std::string CanonicalText() const;
  // The normalised polygons as closed rings (outer counter-clockwise, holes clockwise).
  std::vector<PolygonInput> ToPolygons() const;

 private:
  friend std::vector<float> CellOverlapFractions(const Area&, int, int, double, Point2);
  friend absl::StatusOr<OccupancyMap> RasterizeArea(const Area&, double, RasterRule, int64_t);

  explicit Area(std::shared_ptr<const geometry_internal::AreaData> data) : data_(std::move(data)) {}

  std::shared_ptr<const geometry_internal::AreaData> data_;
};

// Fraction in [0, 1] of each cell covered by `area`, for a rows x cols grid of square cells of
// side `cell` whose cell (r, c) is origin + (c*cell, r*cell) .. + ((c+1)*cell, (r+1)*cell);
// row-major, row 0 = smallest y. Cells the boundary enters are clipped with Boost.Geometry
// (exact up to its overlay precision, about 1e-7 of the area's extent); the others are 0 or 1
// from a scan-line parity test; only cells overlapping the bounding box are visited. About
// 0.1 s for 10^6 cells and a 130-vertex polygon.
// Returns rows*cols zeros when the area is empty or the grid is degenerate (cell <= 0, not
// finite, rows or cols <= 0 gives an empty vector).
std::vector<float> CellOverlapFractions(const Area& area, int rows, int cols, double cell,
                                        Point2 origin);

// How RasterizeArea decides that a pixel is free.
enum class RasterRule {
  kCentre,  // the pixel centre, origin + ((c + 0.5) * res, (r + 0.5) * res), lies in the area
  kInside,  // the whole closed pixel square lies in the closed area (conservative, up to
            // 1e-9 of a pixel), for obstacle checks
};

// Draws the area as free space of an occupancy image of `resolution` m/px: origin =
// floor(min_corner / resolution) * resolution, and width/height reach max_corner. Pixels that
// are not free are kOccupied. InvalidArgument when the area is empty, the resolution is not a
// positive finite number, or the image would exceed `max_pixels`.
absl::StatusOr<OccupancyMap> RasterizeArea(const Area& area, double resolution, RasterRule rule,
                                           int64_t max_pixels = 64'000'000);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_GEOMETRY_AREA_H_
