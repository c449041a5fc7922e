// Random clutter for the replanning evaluation (thesis §4.6): rotated
// rectangles of varied size dropped onto a map's free space until they
// occupy a requested share of it, to make a "true" map the robot discovers
// while driving a plan of the plain one.
//
//   ASSIGN_OR_RETURN(OccupancyMap truth, AddClutter(plain, /*percent=*/10.0, /*seed=*/3));
//   ASSIGN_OR_RETURN(SimulationResult r, Simulate(plain, truth, options));
//
// Thread-safety: stateless free function, safe to call concurrently.
#ifndef COVPLAN_PLANNER_SIM_CLUTTER_H_
#define COVPLAN_PLANNER_SIM_CLUTTER_H_

#include <cstdint>

#include "absl/status/statusor.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

struct ClutterOptions {
  double min_side_m = 0.3;  // rectangle sides are uniform in [min_side_m, max_side_m]
  double max_side_m = 1.5;
  // When > 0: the cell size of a grid (BuildGrid, default options otherwise)
  // that must stay connected: a rectangle that would cut free cells of that
  // grid off its largest component is redrawn. Keeps every map of an
  // evaluation coverable as a whole (a table in a doorway would otherwise cut
  // off a room, and the runs would compare different areas).
  double keep_connected_cell_m = 0.0;
};

// Returns `map` with rectangles (uniform side lengths, uniform orientation,
// centred on a free pixel) drawn as occupied pixels until the newly occupied
// pixels reach `percent` % of the map's free pixels. A rectangle that would
// overshoot the target by more than a quarter of a percentage point is
// redrawn (smaller ones are tried when many are refused), so the result lies
// within [percent, percent + 0.25] % for any map with enough free pixels.
// Deterministic for a seed (std::mt19937_64; the std distributions are fixed
// for one standard library). InvalidArgument for percent outside [0, 50], a
// map without free pixels, bad side lengths or a bad connectivity cell;
// FailedPrecondition when the free space cannot take that much clutter.
absl::StatusOr<OccupancyMap> AddClutter(const OccupancyMap& map, double percent, uint64_t seed,
                                        const ClutterOptions& options = {});

// Sets the pixels of `truth` within the square of half-side `radius_m`
// around `at` to those of `known` (same frame), e.g. to keep clutter off a
// dock. Returns how many pixels that were not free in `truth` became free.
int64_t ClearAround(const OccupancyMap& known, Point2 at, double radius_m, OccupancyMap* truth);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_SIM_CLUTTER_H_
