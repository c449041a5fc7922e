// What a fleet plan is asked for and what it answers: k robots on one site,
// each with its own id, robot model (speeds, turn rate, start and end pose)
// and optional battery, sharing one planner, one tool width, the regions and
// no-go zones; the answer is one ordinary CoveragePlan per robot plus the
// fleet's figures (makespan, its lower bound, shares, the safety report).
//
//   FleetRequest f;
//   f.base.planner = "oarp"; f.base.common.time_limit_s = 2;
//   f.robots.push_back({"r1", model1, std::nullopt});
//   f.robots.push_back({"r2", model2, std::nullopt});
//   ASSIGN_OR_RETURN(FleetPlan plan, PlanFleet(engine, source, f));
//
// Thread-safety: plain value types.
#ifndef COVPLAN_PLANNER_FLEET_FLEET_REQUEST_H_
#define COVPLAN_PLANNER_FLEET_FLEET_REQUEST_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "planner/energy/battery.h"
#include "planner/engine/engine.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/floor_measure.h"
#include "planner/tour/robot_model.h"

namespace covplan {

struct FleetRobot {
  std::string id;
  RobotModel robot;  // tool width: the same for every robot of a fleet
  std::optional<BatteryOptions> battery;
  // Time one recharge at the station takes (battery plans): counted once per
  // charge cycle after the first in the robot's duration.
  double recharge_s = 0.0;
};

enum class FleetDivision : uint8_t {
  // Split one good tour of the whole site into consecutive pieces so that
  // the last robot finishes as early as possible, then rebalance on the
  // robots' real plans (division.h).
  kMakespan = 0,
  // The DARP-style baseline: regions of equal cell count grown from the
  // robots' starts, whatever the time each takes.
  kEqualArea = 1,
};
const char* FleetDivisionName(FleetDivision d);  // "makespan", "equal_area"

struct FleetRequest {
  // Planner, its options, regions, no-go zones, budget, seed and threads,
  // min_free_fraction. Its robot and battery are ignored: each robot brings
  // its own.
  PlanRequest base;
  std::vector<FleetRobot> robots;
  FleetDivision division = FleetDivision::kMakespan;
  // The safety report counts the moments two robots come closer than this
  // (centre to centre, metres). 0: the tool width.
  double clearance_m = 0.0;
  // Empty: cover the whole site (the regions, when given). Else only the
  // cells whose entry is non-zero (Grid::Index on the site's grid): a fleet
  // redividing what is left of a mission.
  std::vector<uint8_t> cover_mask;
  // Empty: the robots drive anywhere on the site's drive grid. Else (with a
  // cover mask) only on the cells whose entry is non-zero: a redivision
  // closes the obstacles the robots reported.
  std::vector<uint8_t> drive_mask;

  static constexpr int kMaxRobots = 64;
  // InvalidArgument naming the field ("robots[2].id", "robots[1].robot.tool_width_m").
  absl::Status Validate() const;
  // The single-robot request robot `i` plans with.
  PlanRequest RobotRequest(size_t i) const;
};

// When two robots, all starting together and following their timed plans,
// come closest, and how often they come closer than the clearance.
struct FleetSafety {
  double clearance_m = 0.0;
  double closest_approach_m = 0.0;  // +inf with fewer than two robots
  double closest_at_s = 0.0;
  std::string closest_pair[2];
  struct Conflict {
    double start_s = 0.0;
    double end_s = 0.0;
    double min_distance_m = 0.0;
    std::string robot_a, robot_b;
  };
  // Each maximal interval during which a pair is closer than clearance_m.
  std::vector<Conflict> conflicts;
  double sample_step_s = 0.0;
};

struct FleetRobotPlan {
  std::string id;
  EngineResult result;         // plan + the area it was planned on (its share)
  int64_t assigned_cells = 0;  // cells of the site given to this robot
  double area_share = 0.0;     // assigned_cells / the site's cells to cover
  double duration_s = 0.0;     // recharges included for battery plans
  bool idle = false;           // given nothing (more robots than work)
};

struct FleetPlan {
  std::vector<FleetRobotPlan> robots;  // in request order
  FleetDivision division = FleetDivision::kMakespan;
  double makespan_s = 0.0;
  double lower_bound_s = 0.0;  // bounds.h
  double gap = 0.0;            // makespan / lower bound - 1
  double sum_duration_s = 0.0;
  int64_t cover_cells = 0;
  int64_t covered_cells = 0;  // distinct cells swept by some robot
  // The floor the tool can reach on the site's map pixels and the share of
  // it the robots' paths sweep together (planner/plan/floor_measure.h). Only
  // for the whole site: all zero for a part (FleetRequest::cover_mask, a
  // redivision).
  FloorMeasure floor;
  int rebalance_rounds = 0;
  // The makespan division kept the equal-area regions (they finished first).
  bool from_regions = false;
  double planning_ms = 0.0;
  Termination termination;
  FleetSafety safety;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_FLEET_REQUEST_H_
