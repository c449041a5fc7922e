// Renders a plan as SVG: the map (if given), blocked grid cells, ranks
// coloured by orientation, transitions dashed, start/end markers.
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_PLAN_SVG_H_
#define COVPLAN_PLANNER_PLAN_SVG_H_

#include <string>

#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"

namespace covplan {

// `map` may be null (only the grid is drawn).
std::string RenderPlanSvg(const CoveragePlan& plan, const OccupancyMap* map);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_SVG_H_
