#include "planner/fleet/units.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>
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
                                           const StopToken& stop, int num_threads) {
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
  // or robots sharing a dock, share one), up to `num_threads` at a time.
  struct Field {
    Pose2 pose;
    CellIndex cell;
    std::vector<double> entry, exit;
  };
  std::vector<Field> fields;
  std::vector<int> start_field(k, -1), end_field(k, -1);
  auto field_of = [&](const Pose2& pose, const std::string& what) -> absl::StatusOr<int> {
    for (size_t i = 0; i < fields.size(); ++i) {
      if (fields[i].pose.x == pose.x && fields[i].pose.y == pose.y) return static_cast<int>(i);
    }
    ASSIGN_OR_RETURN(CellIndex cell, JoinCell(drive, pose, what.c_str()));
    fields.push_back({pose, cell, {}, {}});
    return static_cast<int>(fields.size()) - 1;
  };
  for (int r = 0; r < k; ++r) {
    const RobotModel& robot = robots[r].robot;
    if (robot.start.has_value()) {
      ASSIGN_OR_RETURN(start_field[r],
                       field_of(*robot.start, absl::StrFormat("robots[%d].robot.start", r)));
    }
    if (robot.end.has_value()) {
      ASSIGN_OR_RETURN(end_field[r],
                       field_of(*robot.end, absl::StrFormat("robots[%d].robot.end", r)));
    }
  }
  const double cell = drive.cell_size();
  std::atomic<size_t> next{0};
  std::atomic<bool> cancelled{false};
  auto work = [&] {
    AnyAngleSearch search(drive);
    for (size_t i; (i = next.fetch_add(1)) < fields.size() && !cancelled;) {
      Field& f = fields[i];
      if (!search.Run(f.cell, stop)) {
        cancelled = true;
        return;
      }
      auto at = [&](Point2 p) {
        const CellIndex c = drive.CellAt(p);
        return drive.IsFree(c) && search.Reached(c) ? search.DistanceCells(c) * cell : INFINITY;
      };
      f.entry.resize(n);
      f.exit.resize(n);
      for (int u = 0; u < n; ++u) {
        f.entry[u] = at(units.units[u].entry);
        f.exit[u] = at(units.units[u].exit);
      }
    }
  };
  const int threads = std::clamp<int>(num_threads, 1, std::max<int>(1, fields.size()));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (cancelled) return absl::DeadlineExceededError("fleet: cancelled");
  for (int r = 0; r < k; ++r) {
    const RobotModel& robot = robots[r].robot;
    if (start_field[r] >= 0) {
      const Field& f = fields[start_field[r]];
      const Point2 from{robot.start->x, robot.start->y};
      for (int u = 0; u < n; ++u) {
        const double d = f.entry[u];
        c.reach_[r][u] = std::isfinite(d) ? TripTime(robot, from, robot.start->theta,
                                                     units.units[u].entry, std::nullopt, d)
                                          : INFINITY;
      }
    }
    if (end_field[r] >= 0) {
      const Field& f = fields[end_field[r]];
      const Point2 to{robot.end->x, robot.end->y};
      for (int u = 0; u < n; ++u) {
        const double d = f.exit[u];
        c.ret_[r][u] = std::isfinite(d) ? TripTime(robot, units.units[u].exit,
                                                   units.units[u].exit_heading, to, std::nullopt, d)
                                        : INFINITY;
      }
    }
  }
  return c;
}

}  // namespace covplan
