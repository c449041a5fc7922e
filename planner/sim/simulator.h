// The replanning simulator (thesis §4.6): plan OARP on the map the robot
// knows, then drive that plan under the robot model through the map as it
// really is. A radial range sensor with line of sight reports the cells the
// known map called free that are in fact blocked, and the cells whose
// furniture, too small to block the cell, the path ahead runs into (unless
// closing such a cell would cut the robot off); when they cut the path
// still to drive, OARP-Replan (planner/replan) gives a new plan from where
// the robot is, and the robot drives on along it. The replan's compute time
// beyond what the robot still drives before it meets the obstacle is
// stoppage; total time = drive time + stoppage.
//
//   SimulationOptions o;
//   o.method = ReplanMethod::kAuto;
//   o.plan.robot.tool_width_m = 0.8;
//   ASSIGN_OR_RETURN(SimulationResult r, Simulate(known, truth, o));
//   r.total_time_s, r.stoppage_s, r.covered_free_area_ratio, r.floor, r.driven ...
//   ASSIGN_OR_RETURN(OfflineBound lb, OfflineLowerBound(truth, o.plan));  // OARP knowing
//   everything (offline_bound.h, included here)
//
// Battery plans (options.plan.battery): the plan is split into charge
// cycles on the known map (planner/energy; station legs are ordinary path
// segments of kinds kToStation / kFromStation), the robot drives it, and
// every time a cycle ends at the station it recharges for recharge_s
// (counted for the last cycle too: the robot ends docked and charged).
// SimulationResult::battery tracks the charge along the driven path with the
// plan's energy model (battery_run.h). New obstacles on a battery plan are
// driven around by the greedy detour only, whatever `method` says: it follows
// the old legs, station legs included, and detours around what the sensor
// finds; the other methods would re-tour the remainder without its charge
// stops. The detours cost energy the split did not plan for, and no cycle is
// re-split: battery.cycle_energy, cycles_over_budget, min_battery_left and
// below_reserve report a cycle that no longer fits as it is (the simulated
// robot drives on with a negative charge rather than stop, so the whole run
// stays comparable). The station must lie in a free cell of the true map.
//
// Simulate sets the run up (the true grid, what the sensor can find, the
// plan source) and measures the result against the true map; the run itself
// is drive.h, its sensor sensor.h, the references it is compared with
// offline_bound.h.
//
// Time is simulated; only the replans' compute time is measured (wall
// clock), so stoppage, and with it the plans Algorithm 1 picks, varies a
// little from run to run and with the machine.
// Thread-safety: Simulate is reentrant (each call has its own estimator).
#ifndef COVPLAN_PLANNER_SIM_SIMULATOR_H_
#define COVPLAN_PLANNER_SIM_SIMULATOR_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/floor_measure.h"
#include "planner/replan/replanner.h"
#include "planner/sim/battery_run.h"
#include "planner/sim/offline_bound.h"

namespace covplan {

struct SimulationOptions {
  ReplanMethod method = ReplanMethod::kAuto;
  // Radial range sensor with line of sight over the true map's pixels.
  double sensor_range_m = 5.6;
  // The robot senses at least every step_s of driving and at every waypoint.
  double step_s = 0.1;
  uint64_t seed = 1;  // for the replans (the initial plan uses plan.seed)
  PlanOptions plan;   // robot, tool width, time limit ... of the initial plan
  // ReplanOptions::tour_time_limit_s of every replan: the anytime tour search
  // stops there even when the robot is far from the obstacle.
  double replan_tour_time_limit_s = 1.0;
  // Bounds that make every run end: at most this many replans, and at most
  // max_time_factor x the initial plan's duration + 3600 s of driving.
  int max_replans = 10'000;
  double max_time_factor = 20.0;
  // Battery plans (plan.battery): seconds at the station per charge cycle.
  double recharge_s = 0.0;

  // InvalidArgument naming the field.
  absl::Status Validate() const;
};

struct SimulationResult {
  double total_time_s = 0.0;   // drive_time_s + stoppage_s (+ battery->recharge_time_s)
  double drive_time_s = 0.0;   // the driven path under the robot model
  double stoppage_s = 0.0;     // waiting for replans
  int num_replans = 0;         // Replan calls (one per event of new obstacles on the path)
  int num_encounters = 0;      // entries of the path into new obstacles, over all replans
  int num_greedy_detours = 0;  // encounters handled by greedy detour, over all replans
  int num_turns = 0;
  double path_length_m = 0.0;
  // Free area of the TRUE map inside the cells actually swept, over the true
  // map's free area.
  double covered_free_area_ratio = 0.0;
  double planned_duration_s = 0.0;          // the initial plan's estimated duration
  std::vector<Waypoint> driven;             // the path actually driven
  std::vector<CellIndex> obstacles_found;   // cells found blocked or reported, in order
  std::vector<double> replan_ms;            // compute time of each replan
  std::vector<Point2> replan_points;        // where each replan started
  std::vector<std::string> replan_methods;  // ReplanStats::method of each
  // Length of the driven path inside non-free pixels of the true map. An
  // obstacle smaller than half a cell (a chair leg, a post) leaves its cell
  // free on the true grid; the robot finds one on its path by sight or by
  // touch and reports its cell (num_small_obstacles) unless closing the
  // cell would cut it off from cells it has still to sweep; what is left is
  // those obstacles, the way out of a reported cell the robot stood in, and
  // paths that touch a reported cell's corner. An offline plan of the true
  // map keeps this at 0.
  double length_in_obstacles_m = 0.0;
  // Cells found by touch rather than sight: the next step would have
  // entered them (or, for a small obstacle, the obstacle in them) while the
  // sensor could not see them.
  int num_touch_detections = 0;
  // Cells free on the true grid reported for an obstacle smaller than the
  // cell on the path ahead (by sight or touch).
  int num_small_obstacles = 0;
  // Nothing can stand where the robot starts (it is there) or on its dock:
  // the true map is taken as the known one within a tool width of the
  // plan's start and end poses. truth_cleared_px counts the pixels that
  // freed (clutter dropped onto the parked robot); truth_used is the true
  // map the run drove when that changed anything (null otherwise). Not for
  // battery runs: their station must be free in the true map.
  int64_t truth_cleared_px = 0;
  std::shared_ptr<const OccupancyMap> truth_used;
  // Replanner errors and paths that entered a cell reported blocked, with
  // the input that caused them; each was worked around by a greedy detour.
  std::vector<std::string> problems;
  // The floor the tool can reach on the true map and how much of it the
  // driven path swept (floor_measure.h): seeded from the cells free on both
  // the plan's drive grid and the true grid, in the robot's component as its
  // cell model moves; outside the no-go zones, inside the regions. The
  // plan's own figure (stats.swept_reachable_ratio) is the known map's.
  FloorMeasure floor;
  // Per cell of the plan's grid (Grid::Index): swept by the driven path.
  std::vector<uint8_t> swept;
  bool completed = true;  // false: a bound of SimulationOptions stopped the run
  std::string termination;
  std::optional<BatteryRun> battery;  // battery plans only
};

// Where the simulated robot's plans come from. The default plans and
// replans in process (PlanCoverageWithArea, Replan with an estimator of its
// own); `covplan simulate --server` supplies one that asks a server (the Plan
// RPC, then a Drive session), so the run also exercises the service.
// Thread-safety: used by one simulation at a time.
class PlanSource {
 public:
  virtual ~PlanSource() = default;
  // The plan of the known map. Its `area` may be null (a remote plan); the
  // simulator needs the path, the sweeps and the grid.
  virtual absl::StatusOr<RetainedPlan> InitialPlan(const OccupancyMap& known,
                                                   const PlanOptions& options) = 0;
  // A replan of `plan` (the one being driven). Running out of time is not an
  // error (the greedy detour answers); an error makes the simulator retry
  // with options.method = kGreedyDetour.
  virtual absl::StatusOr<ReplanResult> Replan(const RetainedPlan& plan, const RobotProgress& at,
                                              const Observations& seen,
                                              const ReplanOptions& options) = 0;
  // True when the source wants Moved after every step of the drive.
  virtual bool WatchesMoves() const { return false; }
  // The robot moved: it stands at `at` on the plan it drives, `clock_s`
  // seconds into the run (a watched run paces itself and reports it).
  virtual void Moved(const RobotProgress& at, double clock_s) {}
  // A remote source: how long each reconnect to its planner took, in
  // seconds (the server went away mid-run). Empty in process.
  virtual std::vector<double> ReconnectSeconds() const { return {}; }
};

// InvalidArgument when the options are bad, the maps differ in size,
// resolution or origin, or the battery's station is not in a free cell of
// the true map; errors of the initial plan are passed on. `source`
// (optional, not owned): where plans come from; default in process.
absl::StatusOr<SimulationResult> Simulate(const OccupancyMap& known, const OccupancyMap& truth,
                                          const SimulationOptions& options,
                                          PlanSource* source = nullptr);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_SIM_SIMULATOR_H_
