// The battery of a simulated run: the driven path's energy under the plan's
// energy model (PathEnergy's per-segment rule, SegmentEnergy), cut into the
// charge cycles the robot actually drove. A cycle ends when a kToStation
// segment reaches the station and the robot then leaves on a segment of
// another kind (kFromStation, normally), or when the path ends at the
// station; the battery is then recharged to full, which takes `recharge_s`.
// Passing the station's point on a coverage line, or on a greedy detour to
// the station (its corners are cell centres, as the station may be), is not
// docking. A station on a cell border whose outbound leg is blocked right
// away could be passed without a charge being counted (the detour is then
// kTransition); the cycle then shows as one too long, never as one too short. The lowest
// charge seen shows a run that would have run the battery flat (it may be
// negative: the simulated robot drives on, and says so).
//
//   BatteryRun b = DriveBattery(result.driven, *options.plan.battery, robot, options.recharge_s);
//   b.charge_cycles_driven, b.energy_used, b.min_battery_left, b.below_reserve ...
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_SIM_BATTERY_RUN_H_
#define COVPLAN_PLANNER_SIM_BATTERY_RUN_H_

#include <vector>

#include "planner/energy/battery.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

struct BatteryRun {
  int charge_cycles_planned = 0;  // the initial plan's cycles (filled by the simulator)
  double energy_planned = 0.0;    // the initial plan's energy_total (filled by the simulator)
  int charge_cycles_driven = 0;   // cycles that ended at the station
  double recharge_time_s = 0.0;   // recharge_s per cycle driven
  double energy_used = 0.0;       // along the whole driven path
  double min_battery_left = 0.0;  // lowest charge seen (starts full: capacity)
  bool below_reserve = false;     // the charge went below the reserve at some point
  // Entries of cycle_energy above capacity - reserve (a cycle the plan
  // promised to fit and the detours made too long).
  int cycles_over_budget = 0;
  // Energy of each driven cycle in order, then that of the last stretch if
  // the run did not end at the station.
  std::vector<double> cycle_energy;
  bool ended_at_station = false;
};

// `driven` starts where the robot started (the station, for battery plans).
// Points within 1e-6 m of the station are at it.
BatteryRun DriveBattery(const std::vector<Waypoint>& driven, const BatteryOptions& battery,
                        const RobotModel& robot, double recharge_s);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_SIM_BATTERY_RUN_H_
