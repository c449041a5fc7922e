// Where a path crosses the true map's non-free pixels (internal to
// planner/sim). The cell model keeps a cell free when more than half of it
// is free, so a table leg, a post or a chair's foot leaves its cell free and
// a path through the cell centre may run into it. The simulated robot finds
// such an obstacle as it finds a blocked cell, by sight or by touch, and
// reports its cell (drive.h); LengthInObstacles measures what it still drove
// through.
//
//   std::vector<PathCrossing> ahead = SmallObstacleCrossings(truth, true_grid, path);
//   double bumped_m = LengthInObstacles(truth, driven);
//
// Thread-safety: free functions over const inputs.
#ifndef COVPLAN_PLANNER_SIM_OBSTACLE_CROSSINGS_H_
#define COVPLAN_PLANNER_SIM_OBSTACLE_CROSSINGS_H_

#include <vector>

#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"

namespace covplan::sim_internal {

// The path enters a non-free pixel at `at`, `along_m` metres into segment
// path[segment - 1] -> path[segment], inside `cell`, a cell the grid has free.
struct PathCrossing {
  int segment = 0;
  double along_m = 0.0;
  Point2 at;
  CellIndex cell;
};

// True when `p` lies in the interior of a non-free pixel of `map` (or off
// it): faces and corners of obstacles may be touched.
bool InsideObstacle(const OccupancyMap& map, Point2 p);

// Every entry of `path` (sampled every quarter pixel) into the interior of
// a non-free pixel of `map` that lies in a cell `grid` has free, in path
// order. Entries into cells the grid has blocked are left out: the sensor
// finds those as blocked cells.
std::vector<PathCrossing> SmallObstacleCrossings(const OccupancyMap& map, const Grid& grid,
                                                 const std::vector<Waypoint>& path);

// Length of `path` inside the interior of the non-free pixels of `map`
// (sampled every quarter pixel; faces and corners may be touched).
double LengthInObstacles(const OccupancyMap& map, const std::vector<Waypoint>& path);

}  // namespace covplan::sim_internal

#endif  // COVPLAN_PLANNER_SIM_OBSTACLE_CROSSINGS_H_
