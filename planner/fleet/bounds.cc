#include "planner/fleet/bounds.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace covplan {
namespace {

// Seconds robot `robot` needs to drive unit `u` as the tour does, from its
// entry point already heading along its first segment.
double UnitTime(const TourUnits& units, const TourUnit& u, const RobotModel& robot) {
  double t = 0.0;
  for (int i = u.entry_waypoint + 1; i <= u.exit_waypoint; ++i) {
    const Waypoint& a = units.path[i - 1];
    const Waypoint& b = units.path[i];
    t += robot.StraightTime(std::hypot(b.x - a.x, b.y - a.y));
    if (i > u.entry_waypoint + 1) t += robot.TurnTime(HeadingChange(a.theta, b.theta));
  }
  return t;
}

double Reversed(double heading) { return heading + M_PI; }

// The least total turning (radians) of any path of straight segments and
// turns in place from `a` heading `ha` to `b` heading `hb`
// (docs/fleet.md): at least the net change, and, when the robot moves, the
// way through the displacement's direction d, capped at half a turn (the
// headings a path takes span an arc; under half a turn that arc holds d).
double TurnBound(double ha, double hb, Point2 a, Point2 b) {
  const double net = HeadingChange(ha, hb);
  if (std::hypot(b.x - a.x, b.y - a.y) <= 1e-9) return net;
  const double d = std::atan2(b.y - a.y, b.x - a.x);
  return std::max(net, std::min(M_PI, HeadingChange(ha, d) + HeadingChange(d, hb)));
}

}  // namespace

MakespanBound MakespanLowerBound(const TourUnits& units, const std::vector<FleetRobot>& robots) {
  MakespanBound bound;
  const int n = static_cast<int>(units.units.size());
  const int k = static_cast<int>(robots.size());
  if (n == 0 || k == 0) return bound;
  // The fleet's fastest straight speed and turn rate: a move's lower bound.
  RobotModel fastest = robots[0].robot;
  for (const FleetRobot& r : robots) {
    fastest.max_speed_mps = std::max(fastest.max_speed_mps, r.robot.max_speed_mps);
    fastest.turn_rate_deg_s = std::max(fastest.turn_rate_deg_s, r.robot.turn_rate_deg_s);
    fastest.acceleration_mps2 = std::max(fastest.acceleration_mps2, r.robot.acceleration_mps2);
  }
  auto move = [&](Point2 a, double ha, Point2 b, double hb) {
    const double dist = std::hypot(b.x - a.x, b.y - a.y);
    // Straight moves from rest to rest: their times add up to at least one
    // move of their summed length (StraightTime is concave, zero at zero).
    return fastest.StraightTime(dist) + fastest.TurnTime(TurnBound(ha, hb, a, b));
  };
  // Variant 0: forwards (enter at entry heading entry_heading, leave at exit);
  // variant 1: backwards (enter at exit reversed, leave at entry reversed).
  struct End {
    Point2 in, out;
    double h_in, h_out;
  };
  std::vector<End> ends(2 * n);
  std::vector<std::vector<double>> time(k, std::vector<double>(n));
  double work = 0.0;
  for (int u = 0; u < n; ++u) {
    const TourUnit& t = units.units[u];
    ends[2 * u] = {t.entry, t.exit, t.entry_heading, t.exit_heading};
    ends[2 * u + 1] = {t.exit, t.entry, Reversed(t.exit_heading), Reversed(t.entry_heading)};
    double best = INFINITY;
    for (int r = 0; r < k; ++r) {
      time[r][u] = UnitTime(units, t, robots[r].robot);
      best = std::min(best, time[r][u]);
    }
    work += best;
  }
  // The cheapest way into each unit: from another unit (exits bucketed on a
  // square grid, searched ring by ring until no nearer bucket can beat the
  // best move found), and from a start.
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (const End& e : ends) {
    x0 = std::min(x0, e.out.x), y0 = std::min(y0, e.out.y);
    x1 = std::max(x1, e.out.x), y1 = std::max(y1, e.out.y);
  }
  const double span = std::max({x1 - x0, y1 - y0, 1e-6});
  const int side = std::max(1, static_cast<int>(std::sqrt(2.0 * n)));
  const double bucket = span / side + 1e-9;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(side) * side);
  auto bx = [&](double x) { return std::clamp(static_cast<int>((x - x0) / bucket), 0, side - 1); };
  auto by = [&](double y) { return std::clamp(static_cast<int>((y - y0) / bucket), 0, side - 1); };
  for (int w = 0; w < 2 * n; ++w)
    buckets[by(ends[w].out.y) * side + bx(ends[w].out.x)].push_back(w);
  auto cheapest_in = [&](int u, const End& e) {
    double best = INFINITY;
    const int cx = bx(e.in.x), cy = by(e.in.y);
    for (int ring = 0; ring <= side; ++ring) {
      // Every exit in this ring or beyond is at least this far away.
      const double near = std::max(0, ring - 1) * bucket;
      if (near / fastest.max_speed_mps >= best) break;
      for (int gy = cy - ring; gy <= cy + ring; ++gy) {
        for (int gx = cx - ring; gx <= cx + ring; ++gx) {
          if (std::max(std::abs(gx - cx), std::abs(gy - cy)) != ring) continue;
          if (gx < 0 || gy < 0 || gx >= side || gy >= side) continue;
          for (int w : buckets[gy * side + gx]) {
            if (w / 2 == u) continue;
            best = std::min(best, move(ends[w].out, ends[w].h_out, e.in, e.h_in));
          }
        }
      }
    }
    return best;
  };
  std::vector<double> saving;
  for (int u = 0; u < n; ++u) {
    double from_unit = INFINITY, from_start = INFINITY;
    for (int v = 0; v < 2; ++v) {
      const End& e = ends[2 * u + v];
      from_unit = std::min(from_unit, cheapest_in(u, e));
      for (const FleetRobot& r : robots) {
        if (!r.robot.start.has_value()) {
          from_start = 0.0;
          continue;
        }
        const Pose2& s = *r.robot.start;
        from_start = std::min(from_start, move({s.x, s.y}, s.theta, e.in, e.h_in));
      }
    }
    if (!std::isfinite(from_unit)) from_unit = from_start;  // a single unit
    work += from_unit;
    saving.push_back(std::max(0.0, from_unit - from_start));
  }
  std::sort(saving.begin(), saving.end(), std::greater<>());
  for (int i = 0; i < std::min(k, n); ++i) work -= saving[i];
  bound.work_s = std::max(0.0, work) / k;
  // Some robot must drive each unit, from its start and back to its end.
  for (int u = 0; u < n; ++u) {
    double best = INFINITY;
    for (int r = 0; r < k; ++r) {
      const RobotModel& m = robots[r].robot;
      for (int v = 0; v < 2; ++v) {
        const End& e = ends[2 * u + v];
        double t = time[r][u];
        if (m.start) t += m.StraightTime(std::hypot(e.in.x - m.start->x, e.in.y - m.start->y));
        if (m.end) t += m.StraightTime(std::hypot(e.out.x - m.end->x, e.out.y - m.end->y));
        best = std::min(best, t);
      }
    }
    bound.reach_s = std::max(bound.reach_s, best);
  }
  return bound;
}

}  // namespace covplan
