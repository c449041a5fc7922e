// How much of the real floor a plan sweeps, measured on the map's own
// pixels rather than on the tool-width grid: a cell less than half free
// drops out of the grid, and a rank stops at a cell centre, so the grid's
// "every cell swept" says nothing about the strips along walls and
// furniture.
//
//   reachable: every free pixel a tool disc (diameter = the grid's cell
//              side, the tool width) can touch with its centre at a pixel
//              centre that is at least r + 1/2 pixel from the centre of
//              every non-free pixel and every pixel touching a no-go zone
//              (each such pixel taken as a disc of half a pixel: the tool
//              may graze a pixel's corner by up to 0.21 pixel), in the part
//              of that free space the robot's drive grid lies in (the free
//              space opened by the tool's footprint); with regions, only the
//              pixels more than half inside a region;
//   swept:     every pixel whose centre lies within half a tool width of
//              a point of the plan's path sampled every half pixel (within
//              0.004 pixel of the exact distance at a radius of 8 pixels;
//              the whole path: the tool works while the robot drives).
//
//   ASSIGN_OR_RETURN(FloorReach reach, ComputeFloorReach(*area.drive, no_go, regions));
//   FloorMeasure m = MeasureFloor(reach, plan.path, /*keep_missed=*/false);
//   m.swept_reachable_ratio, m.missed_reachable_m2 ...
//
// Thread-safety: reentrant; FloorReach is immutable once built.
#ifndef COVPLAN_PLANNER_PLAN_FLOOR_MEASURE_H_
#define COVPLAN_PLANNER_PLAN_FLOOR_MEASURE_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/geometry/area.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"

namespace covplan {

// The reachable floor of one coverage area: per map pixel.
struct FloorReach {
  int64_t width = 0;  // pixels; 0: not measurable (a grid without map pixels)
  int64_t height = 0;
  double pixel_m = 0.0;  // side of a pixel
  Point2 origin;         // of pixel (0, 0): the grid's origin
  double tool_radius_px = 0.0;
  std::vector<uint8_t> reachable;  // row-major, row 0 = smallest y
  int64_t reachable_px = 0;
  size_t MemoryBytes() const { return sizeof(*this) + reachable.capacity(); }
};

// From the drive grid's map pixels (Grid::obstacle_pixels) and its free
// cells (the robot's part of the map); `no_go` and `regions` may be null.
// An empty FloorReach (width 0) for a grid without map pixels.
FloorReach ComputeFloorReach(const Grid& drive, const Area* no_go, const Area* regions);
// The same from the map itself, for a drive grid without pixels (a plan
// decoded from its proto, drawn over its map): `map` is the grid's map
// (same origin).
FloorReach ComputeFloorReach(const OccupancyMap& map, const Grid& drive, const Area* no_go,
                             const Area* regions);

struct FloorMeasure {
  double reachable_area_m2 = 0.0;
  double swept_reachable_m2 = 0.0;
  double missed_reachable_m2 = 0.0;
  double swept_reachable_ratio = 0.0;  // swept / reachable; 0 when nothing is reachable
  // With keep_missed: per pixel (as FloorReach::reachable), reachable and
  // not swept.
  std::vector<uint8_t> missed;
};

FloorMeasure MeasureFloor(const FloorReach& reach, const std::vector<Waypoint>& path,
                          bool keep_missed);
// The floor swept by any of `paths` (several robots, or legs driven one
// after the other: no segment joins one path's end to the next's start).
FloorMeasure MeasureFloor(const FloorReach& reach,
                          const std::vector<const std::vector<Waypoint>*>& paths, bool keep_missed);

// Per pixel of a width x height image: 1 when some pixel where `site` is
// non-zero has its centre within sqrt(radius2) pixels of this pixel's centre
// (squared distance <= radius2), else 0. Exact; O(pixels). All 0 when
// `site` does not hold width x height pixels.
std::vector<uint8_t> NearSites(const std::vector<uint8_t>& site, int64_t width, int64_t height,
                               double radius2);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_FLOOR_MEASURE_H_
