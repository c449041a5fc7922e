// Driving a plan through the true map (internal to planner/sim): one
// simulated run. The robot follows its plan under the robot model in steps of
// options.step_s, senses after every step (sensor.h), and when the cells it
// found cut the path still to drive, asks its PlanSource for a replan and
// drives on along that. It accounts the drive time, the stoppage (replan
// compute time the robot cannot drive through), the cells it swept, and the
// problems of the replanner it worked around.
//
//   SimulatedDrive drive(truth, true_grid, options, std::move(plan), candidate, source);
//   ASSIGN_OR_RETURN(SimulationResult r, drive.Run());
//   drive.swept()  // per cell: swept
//
// A run may stop at a given time of its own clock and go on later (a fleet
// whose robot fails redivides the work at that moment, planner/sim/fleet_simulator.h):
//
//   RETURN_IF_ERROR(drive.RunUntil(120.0));  // drive.pose(), drive.swept() at 120 s
//   if (!drive.finished()) ...;              // RunUntil again, or Finish() to stop here
//
// Thread-safety: not thread-safe; one drive per thread (Simulate makes its own).
#ifndef COVPLAN_PLANNER_SIM_DRIVE_H_
#define COVPLAN_PLANNER_SIM_DRIVE_H_

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/engine/engine.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/replan/replanner.h"
#include "planner/sim/obstacle_crossings.h"
#include "planner/sim/sensor.h"
#include "planner/sim/simulator.h"

namespace covplan::sim_internal {

class SimulatedDrive {
 public:
  // `candidate`: per cell, free on the plan's drive grid and blocked on
  // `true_grid` (what the sensor can find). The maps, the options and the
  // source must outlive the drive.
  SimulatedDrive(const OccupancyMap& truth, const Grid& true_grid, const SimulationOptions& options,
                 RetainedPlan plan, std::vector<uint8_t> candidate, PlanSource* source)
      : source_(source),
        truth_(truth),
        grid_(true_grid),
        sensor_(truth, true_grid, options.sensor_range_m),
        options_(options),
        robot_(options.plan.robot),
        method_(options.plan.battery ? ReplanMethod::kGreedyDetour : options.method),
        plan_(std::move(plan)),
        candidate_(std::move(candidate)),
        found_(candidate_.size(), 0),
        pending_flag_(candidate_.size(), 0),
        reported_(candidate_.size(), 0),
        swept_(candidate_.size(), 0) {}

  // Drives the plan to its end (or until a bound of the options stops it).
  // The result has everything but the figures measured against the true map
  // (truth_cleared_px, truth_used, covered_free_area_ratio,
  // length_in_obstacles_m). Internal when
  // a replan fails even as a greedy detour. Call once.
  absl::StatusOr<SimulationResult> Run();
  // Drives on until the run's clock (clock_s) would pass `until_s`, or to the
  // plan's end (or a bound of the options); a later call drives on from
  // there. The robot stops mid-segment at exactly `until_s`, or before a
  // segment whose turn in place would pass it; a robot waiting for a replan
  // waits until `until_s` and the rest of the wait carries over to the next
  // call (Finish drops it: a robot stopped while waiting waited only so
  // long). Errors as Run.
  absl::Status RunUntil(double until_s);
  // The plan's end (or a bound) was reached: nothing is left to drive.
  bool finished() const { return finished_; }
  // Seconds since the run started: straight moves and turns in place under
  // the robot model, plus the stoppage of the replans so far.
  double clock_s() const;
  // Where the robot stands and the heading it drives or last drove.
  Pose2 pose() const;
  // The result so far (as Run's); a run stopped mid-segment ends its driven
  // path where the robot stands. Call once, after the last RunUntil.
  SimulationResult Finish();
  // Per cell of the grid: swept by the driven path.
  const std::vector<uint8_t>& swept() const { return swept_; }
  // Per cell of the grid: found blocked by the sensor (or by touch), or
  // reported for furniture smaller than the cell on the path.
  const std::vector<uint8_t>& found() const { return found_; }

 private:
  const std::vector<Waypoint>& path() const { return plan_.plan.path; }
  int64_t Index(CellIndex c) const { return grid_.Index(c.row, c.col); }
  void Observe(CellIndex c);
  void Sense();
  // Obstacles smaller than their cells (drive_crossings.cc). The path's
  // entries into them (obstacle_crossings.h), found after each plan.
  void FindCrossings();
  // A crossing ahead on the path, in a cell not reported yet (nor found
  // to strand the robot since the last plan).
  bool Ahead(const PathCrossing& x) const;
  // Closing the crossing's cell would cut the robot off from cells it has
  // still to sweep (its own cell: from the neighbour the replanner takes
  // it out to): it does not report it and drives through
  // (length_in_obstacles_m says how far). Remembered until the next plan.
  bool Strands(const PathCrossing& x);
  // Reports the crossings ahead the sensor sees.
  void SenseCrossings();
  // The cell of a crossing ahead on the current segment before `d` metres
  // into it (the bumper found it), counted; none when there is none.
  std::optional<CellIndex> TouchCrossing(double d);
  // Calls f(sample) along the path still to drive until it returns true.
  template <typename F>
  bool ScanRemaining(F f) const;
  bool PendingOnPath() const;
  double TimeToFirstEntry(const std::vector<uint8_t>& flags) const;
  RobotProgress Progress() const;
  absl::Status DoReplan(ReplanMethod method);
  absl::Status HandleViolation(CellIndex cell);
  void PushDriven(const Waypoint& w);
  void IndexSweeps();
  // Marks the cells of the coverage segment being driven that the tool has
  // swept `d` metres into it (its centre at or behind the robot).
  void SweepTo(double d);
  void Start();
  // The clock once the robot, mid-segment, has stopped where it stands: the
  // segment's turn and a straight move of d_seg_ from rest to rest.
  double StopClock() const;
  // One step of the loop: false when the run is over (finished_) or stopped at `until_s`.
  absl::StatusOr<bool> Step(double until_s);
  // A problem line if `path` enters a cell already given to a replan.
  // `kept`: with a walled-in robot's plan, its drive grid (the reported
  // cell kept free there as the way out is not counted).
  std::optional<std::string> CrossesReported(const std::vector<Waypoint>& path,
                                             const Grid* kept = nullptr) const;

  PlanSource* const source_;
  const OccupancyMap& truth_;
  const Grid& grid_;  // the true grid (same frame as the plan's grid)
  const RangeSensor sensor_;
  const SimulationOptions& options_;
  const RobotModel robot_;
  // Battery plans keep their station legs only under the greedy detour.
  const ReplanMethod method_;
  RetainedPlan plan_;
  std::vector<uint8_t> candidate_;     // free on the planned drive grid, blocked on the true one
  std::vector<uint8_t> found_;         // cells the robot has found (candidates, small furniture)
  std::vector<uint8_t> pending_flag_;  // found, not yet given to a replan
  std::vector<uint8_t> reported_;      // given to a replan
  std::vector<CellIndex> pending_;
  std::vector<PathCrossing> crossings_;  // of the current path, in path order
  std::vector<uint8_t> stranding_;       // per cell: closing it would cut the robot off
  bool pending_checked_ = true;          // no pending cell added since PendingOnPath() said no
  std::vector<uint8_t> swept_;
  std::vector<int> sweep_of_;         // per waypoint: index into plan.sweeps or -1
  int seg_ = 1;                       // segment path[seg_-1] -> path[seg_] being driven
  double t_seg_ = 0.0, d_seg_ = 0.0;  // seconds / metres into it
  Point2 pos_;
  CellIndex here_;            // the cell the robot is in (borders are ambiguous)
  bool end_blocked_ = false;  // the plan's end pose lies in a blocked cell
  // The last replan found every cell around the robot blocked and kept its
  // way out free (ReplanStats::robot_cell_kept_free): walled in.
  bool walled_in_ = false;
  bool junction_ = false;  // driven.back() is where a replan cut a segment
  double drive_s_ = 0.0;   // rough drive time, for the time bound
  double clock_s_ = 0.0;   // finished and cut segments (turns included) and stoppage
  double wait_s_ = 0.0;    // stoppage of the last replan not waited out yet
  bool started_ = false;
  bool finished_ = false;
  int planned_cycles_ = 0;
  double planned_energy_ = 0.0;
  double time_cap_ = 0.0;
  int violations_ = 0;
  SimulationResult r_;
};

}  // namespace covplan::sim_internal

#endif  // COVPLAN_PLANNER_SIM_DRIVE_H_
