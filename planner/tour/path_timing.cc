#include "planner/tour/path_timing.h"

#include <cmath>

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

}  // namespace covplan
