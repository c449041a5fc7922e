// Renders a plan as SVG: the map (if given), free grid cells, regions and
// no-go zones, coverage segments coloured by direction, transitions dashed, start/end markers.
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_PLAN_SVG_H_
#define COVPLAN_PLANNER_PLAN_SVG_H_

#include <string>

#include <vector>

#include "planner/geometry/area.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"

namespace covplan {

struct SvgZones {
  std::vector<PolygonInput> regions;  // drawn blue
  std::vector<PolygonInput> no_go;    // drawn red
};

// `map` may be null (only the grid is drawn).
std::string RenderPlanSvg(const CoveragePlan& plan, const OccupancyMap* map,
                          const SvgZones& zones = {});

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_SVG_H_
