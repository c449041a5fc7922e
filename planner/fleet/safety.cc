#include "planner/fleet/safety.h"

#include <algorithm>
#include <cmath>

#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

// Distance covered after `t` seconds of a straight move of `length` metres
// from rest to rest on the robot's trapezoidal profile.
double DistanceAfter(const RobotModel& robot, double length, double t) {
  const double total = robot.StraightTime(length);
  if (t >= total) return length;
  if (t <= 0.0) return 0.0;
  const double a = robot.acceleration_mps2;
  const double v = robot.max_speed_mps;
  double ramp = v / a;  // time to reach top speed
  double peak = v;
  if (a * ramp * ramp > length) {  // triangular: never at top speed
    ramp = std::sqrt(length / a);
    peak = a * ramp;
  }
  if (t <= ramp) return 0.5 * a * t * t;
  const double ramp_len = 0.5 * a * ramp * ramp;
  const double cruise_t = total - 2.0 * ramp;
  if (t <= ramp + cruise_t) return ramp_len + peak * (t - ramp);
  const double left = total - t;
  return length - 0.5 * a * left * left;
}

}  // namespace

TimedPath::TimedPath(const std::vector<Waypoint>& path, const RobotModel& robot,
                     const std::vector<ChargeCycle>& cycles, double recharge_s)
    : path_(path), times_(ArrivalTimes(robot, path, cycles, recharge_s)), robot_(robot) {
  depart_.assign(path.size(), 0.0);
  for (size_t i = 1; i < path.size(); ++i) {
    depart_[i] = times_[i] - robot.StraightTime(
                                 std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y));
  }
}

Point2 TimedPath::At(double t) const {
  if (path_.empty()) return {};
  if (t >= end_time()) return {path_.back().x, path_.back().y};
  const size_t i = std::upper_bound(times_.begin(), times_.end(), t) - times_.begin();
  if (i == 0) return {path_[0].x, path_[0].y};
  const Waypoint& a = path_[i - 1];
  const Waypoint& b = path_[i];
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  if (t <= depart_[i] || len <= 0.0) return {a.x, a.y};
  const double f = DistanceAfter(robot_, len, t - depart_[i]) / len;
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)};
}

FleetSafety FleetSafetyReport(const std::vector<std::string>& ids,
                              const std::vector<TimedPath>& paths, double clearance_m) {
  FleetSafety s;
  s.clearance_m = clearance_m;
  s.closest_approach_m = INFINITY;
  const size_t k = paths.size();
  double horizon = 0.0;
  for (const TimedPath& p : paths) horizon = std::max(horizon, p.end_time());
  // Robots drive at most a few m/s: 0.1 s steps (at most 200,000 of them).
  s.sample_step_s = std::max(0.1, horizon / 200000.0);
  const size_t steps = static_cast<size_t>(std::ceil(horizon / s.sample_step_s)) + 1;
  std::vector<int> open(k * k, -1);  // the conflict each pair is in, or -1
  std::vector<Point2> at(k);
  for (size_t step = 0; step < steps; ++step) {
    const double t = std::min(horizon, step * s.sample_step_s);
    for (size_t r = 0; r < k; ++r) at[r] = paths[r].At(t);
    for (size_t a = 0; a < k; ++a) {
      for (size_t b = a + 1; b < k; ++b) {
        const double d = std::hypot(at[a].x - at[b].x, at[a].y - at[b].y);
        if (d < s.closest_approach_m) {
          s.closest_approach_m = d;
          s.closest_at_s = t;
          s.closest_pair[0] = ids[a];
          s.closest_pair[1] = ids[b];
        }
        int& c = open[a * k + b];
        if (d < clearance_m) {
          if (c < 0) {
            c = static_cast<int>(s.conflicts.size());
            s.conflicts.push_back({t, t, d, ids[a], ids[b]});
          }
          s.conflicts[c].end_s = t;
          s.conflicts[c].min_distance_m = std::min(s.conflicts[c].min_distance_m, d);
        } else {
          c = -1;
        }
      }
    }
  }
  return s;
}

}  // namespace covplan
