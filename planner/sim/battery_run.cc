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
  bool away = false;  // driven away from the station since the last charge
  auto end_cycle = [&] {
    run.cycle_energy.push_back(cycle);
    run.cycles_over_budget += cycle > budget_limit;
    cycle = 0.0;
  };
  for (size_t i = 1; i < driven.size(); ++i) {
    const Waypoint& a = driven[i - 1];
    const Waypoint& b = driven[i];
    const bool moves = std::hypot(b.x - a.x, b.y - a.y) > kAtStationM;
    if (away && at_station(a) && moves) {  // leaving the station after a cycle: recharge first
      end_cycle();
      ++run.charge_cycles_driven;
      run.recharge_time_s += recharge_s;
      level = battery.capacity;
      away = false;
    }
    const double e = SegmentEnergy(a.theta, a, b, battery.energy, robot);
    level -= e;
    cycle += e;
    run.energy_used += e;
    run.min_battery_left = std::min(run.min_battery_left, level);
    if (!at_station(b)) away = true;
  }
  run.ended_at_station = !driven.empty() && at_station(driven.back());
  if (away && run.ended_at_station) {
    // The last cycle ends docked; it recharges too (the robot is ready again).
    end_cycle();
    ++run.charge_cycles_driven;
    run.recharge_time_s += recharge_s;
  } else if (away) {
    end_cycle();  // a stretch that never got back: listed, not counted as driven
  }
  run.below_reserve = run.min_battery_left < reserve_limit;
  return run;
}

}  // namespace covplan
