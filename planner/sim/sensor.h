// The simulated robot's sensor (internal to planner/sim): a radial range
// sensor with line of sight over the true map's pixels. It finds the
// candidate cells (free on the grid the plan was made on, blocked on the true
// grid) whose centre lies within range and in sight of the robot, and tells
// whether a point on an obstacle's border is in range and in sight.
//
//   RangeSensor sensor(truth, true_grid, options.sensor_range_m);
//   for (const CellIndex& c : sensor.Scan(position, candidate, found)) Observe(c);
//
// Thread-safety: immutable after construction; Scan may run on several
// threads. It keeps references to the map and the grid, which must outlive it.
#ifndef COVPLAN_PLANNER_SIM_SENSOR_H_
#define COVPLAN_PLANNER_SIM_SENSOR_H_

#include <cstdint>
#include <vector>

#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"

namespace covplan::sim_internal {

class RangeSensor {
 public:
  // `true_grid` is the true map's grid, in the frame of the plan's grid.
  RangeSensor(const OccupancyMap& truth, const Grid& true_grid, double range_m)
      : truth_(truth), grid_(true_grid), range_m_(range_m) {}

  // The cells with `candidate` set and `found` not (both per cell of the
  // grid) that the robot at `position` sees, row by row from the bottom.
  std::vector<CellIndex> Scan(Point2 position, const std::vector<uint8_t>& candidate,
                              const std::vector<uint8_t>& found) const;
  // The robot at `from` sees the point `to` (a point on an obstacle's
  // border): within range, no non-free pixel between them but the one `to`
  // lies in.
  bool Sees(Point2 from, Point2 to) const;

 private:
  bool Visible(Point2 from, CellIndex target) const;
  // No non-free pixel on the line from `from` to `to` (the pixel of `from`
  // left out) but those whose centre `may_block` accepts.
  template <typename F>
  bool LineOfSight(Point2 from, Point2 to, F may_block) const;

  const OccupancyMap& truth_;
  const Grid& grid_;
  const double range_m_;
};

}  // namespace covplan::sim_internal

#endif  // COVPLAN_PLANNER_SIM_SENSOR_H_
