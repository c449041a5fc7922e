// Renders the plans of a fleet (several robots on one site) as one SVG: the
// site as RenderPlanSvg draws it (svg.h), then per robot, in its own colour
// (FleetSvgColour, cycling after eight robots), the cells its coverage
// sweeps (a light tint: the robot's share), its coverage segments (solid),
// transitions and station legs (dashed), its start (a disc outlined in black)
// and its end (a ring); above the map a legend with each robot's id and
// duration.
//
//   std::vector<FleetSvgRobot> robots = {{"r1", &plan1, 310.0}, {"r2", &plan2, 295.5}};
//   std::string svg = RenderFleetSvg(robots, *plan1.grid, &map, zones, "makespan 310 s");
//
// Does not know planner/fleet (a lower layer): any set of CoveragePlans on
// one grid can be drawn together.
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_PLAN_FLEET_SVG_H_
#define COVPLAN_PLANNER_PLAN_FLEET_SVG_H_

#include <string>
#include <vector>

#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/svg.h"

namespace covplan {

struct FleetSvgRobot {
  std::string id;
  const CoveragePlan* plan = nullptr;  // not owned; null draws nothing but the legend entry
  double duration_s = 0.0;             // shown in the legend
};

// The colour of robot `i` ("#rrggbb"): eight distinguishable colours, then
// the same eight again.
const char* FleetSvgColour(size_t i);
inline constexpr size_t kFleetSvgColours = 8;

// `grid` is the drive grid the plans were planned on (cells swept are read
// from each plan's sweeps, indexed on it); `map` may be null (only the grid
// is drawn). `title`, when not empty, leads the legend (e.g. the makespan).
std::string RenderFleetSvg(const std::vector<FleetSvgRobot>& robots, const Grid& grid,
                           const OccupancyMap* map, const SvgZones& zones = {},
                           const std::string& title = "");

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_FLEET_SVG_H_
