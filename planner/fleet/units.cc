#include "planner/fleet/units.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"

namespace covplan {

TourUnits UnitsOfPlan(const CoveragePlan& plan, const Grid& grid) {
  TourUnits out;
  out.path = plan.path;
  std::vector<uint8_t> taken(static_cast<size_t>(grid.size()), 0);
  int last_tag = -2;
  for (const CoverageSweep& sweep : plan.sweeps) {
    const Waypoint& w = plan.path[sweep.waypoint];
    // A new unit at each new tag (untagged sweeps are units of their own).
    if (out.units.empty() || w.rank != last_tag || w.rank < 0) {
      TourUnit u;
      u.entry_waypoint = std::max(0, sweep.waypoint - 1);
      const Waypoint& e = plan.path[u.entry_waypoint];
      u.entry = {e.x, e.y};
      u.entry_heading = w.theta;
      out.units.push_back(std::move(u));
    }
    TourUnit& u = out.units.back();
    u.exit_waypoint = sweep.waypoint;
    u.exit = {w.x, w.y};
    u.exit_heading = w.theta;
    for (const CellIndex& c : sweep.cells) {
      if (!grid.InBounds(c.row, c.col)) continue;
      const int64_t i = grid.Index(c.row, c.col);
      if (taken[i]) continue;
      taken[i] = 1;
      u.cells.push_back(i);
      ++out.cells;
    }
    last_tag = w.rank;
  }
  // A unit whose cells were all swept before keeps its place in the tour
  // (its entry and exit still order the pieces) with no cells.
  return out;
}

namespace {

// Seconds from a pose to every cell of `drive` (any-angle distance driven at
// the robot's speed, one turn onto the straight line): +inf where unreachable.
absl::StatusOr<AnyAngleSearch*> SearchFrom(AnyAngleSearch* search, const Grid& drive,
                                           const Pose2& pose, const std::string& what,
                                           const StopToken& stop) {
  ASSIGN_OR_RETURN(CellIndex cell, JoinCell(drive, pose, what.c_str()));
  if (!search->Run(cell, stop)) return absl::DeadlineExceededError("fleet: cancelled");
  return search;
}

double TripTime(const RobotModel& robot, Point2 a, std::optional<double> heading_a, Point2 b,
                std::optional<double> heading_b, double path_m) {
  const double straight = std::hypot(b.x - a.x, b.y - a.y);
  double t = robot.StraightTime(std::max(path_m, straight));
  if (straight > 1e-9) {
    const double dir = std::atan2(b.y - a.y, b.x - a.x);
    if (heading_a) t += robot.TurnTime(HeadingChange(*heading_a, dir));
    if (heading_b) t += robot.TurnTime(HeadingChange(dir, *heading_b));
  }
  return t;
}

}  // namespace

absl::StatusOr<UnitCosts> UnitCosts::Build(const TourUnits& units, const Grid& drive,
                                           const std::vector<FleetRobot>& robots,
                                           const StopToken& stop) {
  UnitCosts c;
  const int n = static_cast<int>(units.units.size());
  const int k = static_cast<int>(robots.size());
  c.num_units_ = n;
  c.reach_.assign(k, std::vector<double>(n, 0.0));
  c.ret_.assign(k, std::vector<double>(n, 0.0));
  c.move_.assign(k, std::vector<double>(n, 0.0));
  c.prefix_.assign(k, std::vector<double>(2 * n + 1, 0.0));
  c.scale_.assign(k, 1.0);
  for (int r = 0; r < k; ++r) {
    const RobotModel& robot = robots[r].robot;
    // Time along the reference tour, re-timed with this robot's model.
    std::vector<double> along(units.path.size(), 0.0);
    for (size_t i = 1; i < units.path.size(); ++i) {
      const Waypoint& a = units.path[i - 1];
      const Waypoint& b = units.path[i];
      along[i] = along[i - 1] + robot.TurnTime(HeadingChange(a.theta, b.theta)) +
                 robot.StraightTime(std::hypot(b.x - a.x, b.y - a.y));
    }
    std::vector<double> own(n);
    for (int u = 0; u < n; ++u) {
      const TourUnit& t = units.units[u];
      own[u] = along[t.exit_waypoint] - along[t.entry_waypoint];
      if (u + 1 < n) {
        c.move_[r][u] = along[units.units[u + 1].entry_waypoint] - along[t.exit_waypoint];
      } else if (n > 1) {  // back to the first unit: straight line
        const TourUnit& f = units.units[0];
        c.move_[r][u] = TripTime(robot, t.exit, t.exit_heading, f.entry, f.entry_heading, 0.0);
      }
    }
    for (int m = 0; m < 2 * n; ++m) {
      c.prefix_[r][m + 1] = c.prefix_[r][m] + own[m % n] + c.move_[r][m % n];
    }
  }
  // Distances (metres) from each distinct pose to every unit's entry and
  // exit: one any-angle search per pose (a robot that ends where it starts,
  // or robots sharing a dock, share one).
  AnyAngleSearch search(drive);
  const double cell = drive.cell_size();
  struct Field {
    double x, y;
    std::vector<double> entry, exit;
  };
  std::vector<Field> fields;
  auto field = [&](const Pose2& pose, const std::string& what) -> absl::StatusOr<const Field*> {
    for (const Field& f : fields) {
      if (f.x == pose.x && f.y == pose.y) return &f;
    }
    ASSIGN_OR_RETURN(AnyAngleSearch * s, SearchFrom(&search, drive, pose, what, stop));
    Field f{pose.x, pose.y, std::vector<double>(n), std::vector<double>(n)};
    auto at = [&](Point2 p) {
      const CellIndex c = drive.CellAt(p);
      return drive.IsFree(c) && s->Reached(c) ? s->DistanceCells(c) * cell : INFINITY;
    };
    for (int u = 0; u < n; ++u) {
      f.entry[u] = at(units.units[u].entry);
      f.exit[u] = at(units.units[u].exit);
    }
    fields.push_back(std::move(f));
    return &fields.back();
  };
  fields.reserve(2 * k);
  for (int r = 0; r < k; ++r) {
    const RobotModel& robot = robots[r].robot;
    if (robot.start.has_value()) {
      ASSIGN_OR_RETURN(const Field* f,
                       field(*robot.start, absl::StrFormat("robots[%d].robot.start", r)));
      const Point2 from{robot.start->x, robot.start->y};
      for (int u = 0; u < n; ++u) {
        const double d = f->entry[u];
        c.reach_[r][u] = std::isfinite(d) ? TripTime(robot, from, robot.start->theta,
                                                     units.units[u].entry, std::nullopt, d)
                                          : INFINITY;
      }
    }
    if (robot.end.has_value()) {
      ASSIGN_OR_RETURN(const Field* f,
                       field(*robot.end, absl::StrFormat("robots[%d].robot.end", r)));
      const Point2 to{robot.end->x, robot.end->y};
      for (int u = 0; u < n; ++u) {
        const double d = f->exit[u];
        c.ret_[r][u] = std::isfinite(d) ? TripTime(robot, units.units[u].exit,
                                                   units.units[u].exit_heading, to, std::nullopt, d)
                                        : INFINITY;
      }
    }
  }
  return c;
}

}  // namespace covplan
