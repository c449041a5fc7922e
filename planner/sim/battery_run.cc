#include "planner/sim/battery_run.h"

#include <algorithm>
#include <cmath>

namespace covplan {

BatteryRun DriveBattery(const std::vector<Waypoint>& driven, const BatteryOptions& battery,
                        const RobotModel& robot, double recharge_s) {
  constexpr double kAtStationM = 1e-6;
  auto at_station = [&](const Waypoint& w) {
    return std::hypot(w.x - battery.station.x, w.y - battery.station.y) <= kAtStationM;
  };
  // The split's own tolerance (charge_cycles.cc) for "fits the budget".
  const double budget_limit = battery.budget() * (1 + 1e-9) + 1e-9;
  const double reserve_limit = battery.reserve - 1e-9 * std::max(1.0, battery.capacity);
  BatteryRun run;
  double level = battery.capacity, cycle = 0.0;
  run.min_battery_left = level;
  // A cycle ends with a kToStation segment that reaches the station and is
  // followed by a move of another kind (normally kFromStation) or by the end
  // of the path. A coverage line or a detour may pass the station's point
  // without docking (detour corners are cell centres, as a station may be).
  // The turn onto the station's heading still belongs to the cycle.
  bool docked = false;
  auto end_cycle = [&] {
    run.cycle_energy.push_back(cycle);
    run.cycles_over_budget += cycle > budget_limit;
    ++run.charge_cycles_driven;
    run.recharge_time_s += recharge_s;
    cycle = 0.0;
    docked = false;
  };
  for (size_t i = 1; i < driven.size(); ++i) {
    const Waypoint& a = driven[i - 1];
    const Waypoint& b = driven[i];
    if (docked && std::hypot(b.x - a.x, b.y - a.y) > kAtStationM) {
      if (b.kind == SegmentKind::kToStation) {
        docked = false;  // a detour to the station that passed its point: still on the way
      } else {           // leaving: recharged first
        end_cycle();
        level = battery.capacity;
      }
    }
    const double e = SegmentEnergy(a.theta, a, b, battery.energy, robot);
    level -= e;
    cycle += e;
    run.energy_used += e;
    run.min_battery_left = std::min(run.min_battery_left, level);
    if (b.kind == SegmentKind::kToStation && at_station(b)) docked = true;
  }
  run.ended_at_station = !driven.empty() && at_station(driven.back());
  if (docked || (run.ended_at_station && cycle > 0.0)) {
    // The last cycle ends at the station (the plan's end); it recharges too:
    // the robot is ready again.
    end_cycle();
  } else if (cycle > 0.0) {
    // A stretch that never got back: listed, not counted as a cycle driven.
    run.cycle_energy.push_back(cycle);
    run.cycles_over_budget += cycle > budget_limit;
  }
  run.below_reserve = run.min_battery_left < reserve_limit;
  return run;
}

}  // namespace covplan
