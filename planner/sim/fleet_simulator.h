// A fleet driven through the true map, with robots that fail: the fleet is
// planned on the known map (PlanFleet, planner/fleet), every robot drives its
// plan through the true map as one simulated robot does (simulator.h: a range
// sensor, replanning around what it finds), and when a robot fails at time
// t_f it stops for good; every cell of the mission not yet swept by any robot
// and not found blocked is divided again (PlanFleet with that cover mask, on
// the known map with the cells found blocked so far drawn in) among the
// surviving robots, each starting where it stands at t_f and ending at its
// own end pose. The survivors drive those plans (sensing and replanning
// again) to the end, or to the next failure.
//
//   FleetSimulationOptions o;
//   o.fleet.base.planner = "oarp";  o.fleet.base.common.time_limit_s = 1;
//   o.fleet.robots = {robot_a, robot_b, robot_c};  // each with start and end
//   o.sim.sensor_range_m = 5.6;                    // the single-robot knobs
//   o.failures = {{"b", 120.0}};
//   ASSIGN_OR_RETURN(FleetSimulationResult r, SimulateFleet(known, truth, o));
//   r.makespan_s, r.redivisions[0].plan.makespan_s, r.unswept_reachable_cells
//
// Time is simulated per robot (drive, turns, replan stoppage: simulator.h);
// robots do not see each other (no shared obstacles while they drive, no
// collisions); the obstacles every robot found are shared at a redivision.
// A redivision itself takes no simulated time.
//
// Thread-safety: SimulateFleet is reentrant (each call has its own engine).
#ifndef COVPLAN_PLANNER_SIM_FLEET_SIMULATOR_H_
#define COVPLAN_PLANNER_SIM_FLEET_SIMULATOR_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/fleet/fleet_request.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/floor_measure.h"
#include "planner/sim/simulator.h"

namespace covplan {

struct RobotFailure {
  std::string robot_id;
  double time_s = 0.0;  // simulated seconds after the mission's start
};

struct FleetSimulationOptions {
  // The robots (id, model with start and end pose), planner and options,
  // budget (time_limit_s: the initial plan and each redivision), seed,
  // min_free_fraction, regions, no-go zones. No batteries.
  FleetRequest fleet;
  // The single-robot knobs every robot drives with: method, sensor_range_m,
  // step_s, seed, replan_tour_time_limit_s, max_replans, max_time_factor.
  // Its `plan` is ignored (the fleet request says how to plan).
  SimulationOptions sim;
  std::vector<RobotFailure> failures;  // any order; at most one per robot

  // InvalidArgument naming the field ("failures[1].robot_id").
  absl::Status Validate() const;
};

// One plan a robot drove: its initial share, or its share of a redivision.
struct FleetLeg {
  double start_s = 0.0;      // the mission's time when the robot set off on it
  double end_s = 0.0;        // when it reached the plan's end, failed or took a new plan
  CoveragePlan plan;         // as planned (the replans are in run.driven)
  SimulationResult run;      // the drive (its times count from start_s)
  bool interrupted = false;  // stopped before the plan's end (failure or redivision)
};

struct FleetRobotRun {
  std::string id;
  std::vector<FleetLeg> legs;    // in time order; empty for a robot given nothing at all
  std::vector<Waypoint> driven;  // every leg's driven path, joined
  bool failed = false;
  double failed_at_s = -1.0;   // its failure's time (its last leg not interrupted: it had ended)
  double finish_s = 0.0;       // when it stopped for good (its end, or its failure)
  std::vector<uint8_t> swept;  // per cell (Grid::Index): swept by this robot
  int64_t swept_cells = 0;     // distinct cells it swept
  int num_replans = 0;
  double stoppage_s = 0.0;
  double length_in_obstacles_m = 0.0;
};

struct FleetRedivision {
  double time_s = 0.0;
  std::string failed_robot;
  // Per cell (Grid::Index): still to cover at time_s (in the mission, swept
  // by nobody, not found blocked). Empty when nothing was left.
  std::vector<uint8_t> left;
  int64_t left_cells = 0;
  std::vector<std::string> robots;  // the survivors it divided among
  // PlanFleet of `left` among them; no robots when nothing was left, no
  // survivor was, or the obstacles found had cut every cell left off.
  FleetPlan plan;
  // The survivors' last finish after time_s, minus time_s: to compare with
  // plan.makespan_s (the fresh plan's estimate of the same work). A later
  // failure of a survivor cuts it short.
  double achieved_s = 0.0;
};

struct FleetSimulationResult {
  FleetPlan initial;                  // the fleet plan of the known map
  std::vector<FleetRobotRun> robots;  // in request order
  std::vector<FleetRedivision> redivisions;
  double makespan_s = 0.0;    // the latest finish
  int64_t mission_cells = 0;  // cells to cover on the known map
  int64_t swept_cells = 0;    // distinct cells any robot swept
  // Free cells of the true grid among the mission's, connected to a robot's
  // start over such cells through the known map's walls (the robots' cell
  // model) but for the cells a robot reported for an obstacle smaller than
  // the cell, and of these the ones nobody swept (0 when all went well).
  int64_t reachable_cells = 0;
  int64_t unswept_reachable_cells = 0;
  std::vector<CellIndex> unswept_reachable;  // those cells
  std::vector<uint8_t> swept;                // per cell: swept by some robot
  double covered_free_area_ratio = 0.0;      // of the true map's free area
  double length_in_obstacles_m = 0.0;        // summed over the robots
  // The floor the tool can reach on the true map from those cells (the
  // robots' connected part, outside the no-go zones, inside the regions;
  // floor_measure.h) and how much of it all driven paths swept.
  FloorMeasure floor;
  std::vector<std::string> problems;  // every leg's, prefixed with the robot's id
  bool completed = true;              // false: a bound of the options stopped a leg
  // The true map the robots drove when clearing their start and end poses
  // changed it (see SimulationResult::truth_used), else null.
  std::shared_ptr<const OccupancyMap> truth_used;
};

// InvalidArgument for bad options, maps that do not share a frame, an
// unknown robot in a failure; errors of the fleet plans are passed on.
absl::StatusOr<FleetSimulationResult> SimulateFleet(const OccupancyMap& known,
                                                    const OccupancyMap& truth,
                                                    const FleetSimulationOptions& options);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_SIM_FLEET_SIMULATOR_H_
