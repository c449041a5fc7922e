#include "planner/tour/path_timing.h"

#include <cmath>
#include <cstdint>

namespace covplan {

PolylineTiming TimePolyline(const RobotModel& robot, const std::vector<Point2>& points,
                            std::optional<double> heading_in, std::optional<double> heading_out) {
  PolylineTiming t;
  std::optional<double> heading = heading_in;
  auto turn_to = [&](double h) {
    if (heading) {
      const double change = HeadingChange(*heading, h);
      if (change > kTurnEpsilonRad) {
        t.turn_time_s += robot.TurnTime(change);
        ++t.turns;
      }
    }
    heading = h;
  };
  for (size_t i = 1; i < points.size(); ++i) {
    const double dx = points[i].x - points[i - 1].x, dy = points[i].y - points[i - 1].y;
    const double len = std::hypot(dx, dy);
    if (len < kMinSegmentM) continue;
    turn_to(std::atan2(dy, dx));
    t.length_m += len;
    t.time_s += robot.StraightTime(len);
  }
  if (heading_out) turn_to(*heading_out);
  t.time_s += t.turn_time_s;
  t.final_heading = heading.value_or(0.0);
  return t;
}

std::vector<double> ArrivalTimes(const RobotModel& robot, const std::vector<Waypoint>& path,
                                 const std::vector<ChargeCycle>& cycles, double recharge_s) {
  std::vector<double> times(path.size(), 0.0);
  std::vector<uint8_t> charge_at(path.size(), 0);
  for (size_t c = 0; c + 1 < cycles.size(); ++c) {
    const int w = cycles[c].last_waypoint;
    if (w >= 0 && static_cast<size_t>(w) < path.size()) charge_at[w] = 1;
  }
  double t = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    if (charge_at[i - 1]) t += recharge_s;
    const double change = HeadingChange(path[i - 1].theta, path[i].theta);
    if (change > kTurnEpsilonRad) t += robot.TurnTime(change);
    t += robot.StraightTime(std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y));
    times[i] = t;
  }
  return times;
}

}  // namespace covplan
