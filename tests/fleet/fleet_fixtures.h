// Test helpers for fleet plans: maps drawn in ASCII, engines over them, and
// the checks every fleet plan must pass.
#ifndef COVPLAN_TESTS_FLEET_FLEET_FIXTURES_H_
#define COVPLAN_TESTS_FLEET_FLEET_FIXTURES_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"
#include "planner/fleet/fleet_planner.h"
#include "tests/testing/plan_conformance.h"

namespace covplan::testing {

// One character per `px` x `px` pixels at `res` m/px; '#' wall, anything else
// free. The first string is the top row.
inline OccupancyMap AsciiMap(const std::vector<std::string>& rows, int px, double res) {
  const int h = static_cast<int>(rows.size()) * px;
  const int w = static_cast<int>(rows[0].size()) * px;
  OccupancyMap map(w, h, res, {0.0, 0.0});
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const char ch = rows[rows.size() - 1 - r / px][c / px];
      map.set(r, c, ch == '#' ? CellState::kOccupied : CellState::kFree);
    }
  }
  return map;
}

inline MapSource SourceOfMap(const OccupancyMap& map, const std::string& id) {
  MapSource s;
  s.map_id = id;
  s.load = [&map]() -> absl::StatusOr<SiteMap> {
    SiteMap site;
    site.raster = std::make_shared<const OccupancyMap>(map);
    return site;
  };
  return s;
}

inline FleetRobot Robot(const std::string& id, double tool, double x, double y) {
  FleetRobot r;
  r.id = id;
  r.robot.tool_width_m = tool;
  r.robot.start = Pose2{x, y, 0.0};
  r.robot.end = r.robot.start;
  return r;
}

// Each robot's plan conforms on its own share; together they sweep every cell
// of `whole` (the site's coverage area); the figures agree with the plans.
inline std::string CheckFleetPlan(const FleetPlan& fleet, const FleetRequest& request,
                                  const CoverageArea& whole) {
  std::vector<uint8_t> swept(static_cast<size_t>(whole.drive->size()), 0);
  double makespan = 0.0;
  for (size_t i = 0; i < fleet.robots.size(); ++i) {
    const FleetRobotPlan& rp = fleet.robots[i];
    if (rp.id != request.robots[i].id) return "robot ids out of request order";
    if (rp.idle) continue;
    const std::string err = CheckPlanConformance(rp.result.plan, *rp.result.area,
                                                 request.robots[i].robot, request.base.no_go);
    if (!err.empty()) return absl::StrFormat("robot %s: %s", rp.id, err);
    const Pose2& start = *request.robots[i].robot.start;
    const Waypoint& first = rp.result.plan.path.front();
    if (std::hypot(first.x - start.x, first.y - start.y) > 1e-9)
      return absl::StrFormat("robot %s does not start at its start pose", rp.id);
    for (const CoverageSweep& s : rp.result.plan.sweeps) {
      for (const CellIndex& c : s.cells) swept[whole.drive->Index(c.row, c.col)] = 1;
    }
    makespan = std::max(makespan, rp.duration_s);
  }
  for (int64_t i = 0; i < whole.cover->size(); ++i) {
    if (whole.cover->free_flags()[i] && !swept[i]) {
      const CellIndex c = whole.cover->FromIndex(i);
      return absl::StrFormat("cell (%d, %d) is swept by no robot", c.row, c.col);
    }
  }
  if (std::abs(makespan - fleet.makespan_s) > 1e-6) return "makespan is not the longest duration";
  if (fleet.lower_bound_s <= 0.0 || fleet.lower_bound_s > fleet.makespan_s + 1e-6)
    return absl::StrFormat("lower bound %g is not in (0, makespan %g]", fleet.lower_bound_s,
                           fleet.makespan_s);
  return "";
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_FLEET_FLEET_FIXTURES_H_
