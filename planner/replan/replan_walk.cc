#include "planner/replan/replan_walk.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/path_timing.h"

namespace covplan::replan_internal {
namespace {

double Param(Point2 a, Point2 b, Point2 p) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  if (len2 <= 0.0) return 0.0;
  return std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0);
}

Point2 Lerp(Point2 a, Point2 b, double t) { return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}; }

bool Finite(Point2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }

}  // namespace

absl::StatusOr<Located> Locate(const CoveragePlan& plan, const RobotProgress& progress) {
  const std::vector<Waypoint>& path = plan.path;
  const int n = static_cast<int>(path.size());
  if (n < 2) return absl::FailedPreconditionError("the plan has no path to continue");
  Located at;
  if (progress.distance_m.has_value()) {
    const double d = *progress.distance_m;
    if (!std::isfinite(d) || d < 0.0) {
      return absl::InvalidArgumentError(
          absl::StrFormat("progress.distance_m must be a finite distance >= 0, got %g", d));
    }
    double cum = 0.0;
    for (int i = 1; i < n; ++i) {
      const double len = std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
      if (d <= cum + len + 1e-9) {
        at.segment = i;
        at.t = len > 0 ? std::clamp((d - cum) / len, 0.0, 1.0) : 1.0;
        break;
      }
      cum += len;
      if (i == n - 1) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "progress.distance_m %g is past the end of the path (%.3f m long)", d, cum));
      }
    }
  } else if (progress.waypoint >= 0) {
    if (progress.waypoint < 1 || progress.waypoint >= n) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "progress.waypoint %d is outside the path: the robot drives segment k ending at "
          "waypoint k in [1, %d]",
          progress.waypoint, n - 1));
    }
    if (!progress.position.has_value() || !Finite(*progress.position)) {
      return absl::InvalidArgumentError(
          "progress.position: a finite x, y is required with progress.waypoint");
    }
    const Waypoint& a = path[progress.waypoint - 1];
    const Waypoint& b = path[progress.waypoint];
    at.segment = progress.waypoint;
    at.t = Param({a.x, a.y}, {b.x, b.y}, *progress.position);
    const Point2 q = Lerp({a.x, a.y}, {b.x, b.y}, at.t);
    const double off = std::hypot(q.x - progress.position->x, q.y - progress.position->y);
    const double tol = progress.tolerance_m.value_or(plan.grid ? plan.grid->cell_size() : 1.0);
    if (!(tol >= 0.0) || off > tol) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "progress.position (%.3f, %.3f) is %.3f m from segment %d of the path (tolerance %.3f m)",
          progress.position->x, progress.position->y, off, progress.waypoint, tol));
    }
  } else {
    return absl::InvalidArgumentError(
        "progress: give the segment (waypoint) with the position, or distance_m along the path");
  }
  const Waypoint& a = path[at.segment - 1];
  const Waypoint& b = path[at.segment];
  at.at = Lerp({a.x, a.y}, {b.x, b.y}, at.t);
  at.heading =
      std::hypot(b.x - a.x, b.y - a.y) > kMinSegmentM ? std::atan2(b.y - a.y, b.x - a.x) : b.theta;
  return at;
}

absl::StatusOr<std::vector<uint8_t>> BlockedCells(const Grid& drive, const Observations& obs) {
  std::vector<uint8_t> blocked(static_cast<size_t>(drive.size()), 0);
  auto block = [&](int r, int c) {
    if (drive.IsFree(r, c)) blocked[drive.Index(r, c)] = 1;
  };
  for (size_t k = 0; k < obs.cells.size(); ++k) {
    const CellIndex c = obs.cells[k];
    if (!drive.InBounds(c.row, c.col)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("obstacles.cells[%d] (%d, %d) lies outside the %d x %d grid", k, c.row,
                          c.col, drive.rows(), drive.cols()));
    }
    block(c.row, c.col);
  }
  for (size_t k = 0; k < obs.points.size(); ++k) {
    if (!Finite(obs.points[k])) {
      return absl::InvalidArgumentError(
          absl::StrFormat("obstacles.points[%d] is not a finite point", k));
    }
    const CellIndex c = drive.CellAt(obs.points[k]);
    if (drive.InBounds(c.row, c.col)) block(c.row, c.col);  // points off the map are ignored
  }
  if (!obs.polygons.empty()) {
    absl::StatusOr<Area> area = Area::Create(obs.polygons, "obstacles.polygons");
    if (!area.ok()) return area.status();
    const std::vector<float> f =
        CellOverlapFractions(*area, drive.rows(), drive.cols(), drive.cell_size(), drive.origin());
    for (int64_t i = 0; i < drive.size(); ++i) {
      if (f[i] > 0.0f) {
        const CellIndex c = drive.FromIndex(i);
        block(c.row, c.col);
      }
    }
  }
  return blocked;
}

std::vector<Leg> RemainingLegs(const CoveragePlan& plan, const Located& at,
                               std::vector<uint8_t>* covered) {
  const Grid& grid = *plan.grid;
  covered->assign(static_cast<size_t>(grid.size()), 0);
  std::unordered_map<int, const CoverageSweep*> sweep_at;
  for (const CoverageSweep& s : plan.sweeps) sweep_at[s.waypoint] = &s;
  std::vector<Leg> legs;
  for (int i = 1; i < static_cast<int>(plan.path.size()); ++i) {
    const Waypoint& wa = plan.path[i - 1];
    const Waypoint& wb = plan.path[i];
    const Point2 a{wa.x, wa.y}, b{wb.x, wb.y};
    auto it = sweep_at.find(i);
    const std::vector<CellIndex> none;
    const std::vector<CellIndex>& cells = it == sweep_at.end() ? none : it->second->cells;
    if (i < at.segment) {
      for (const CellIndex& c : cells) (*covered)[grid.Index(c.row, c.col)] = 1;
      continue;
    }
    Leg leg;
    leg.a = i == at.segment ? at.at : a;
    leg.b = b;
    leg.kind = wb.kind;
    leg.old_segment = i;
    leg.tag = wb.rank;
    leg.whole = i != at.segment || at.t <= 0.0;
    for (const CellIndex& c : cells) {
      const double tc = Param(a, b, grid.CellCenter(c));
      if (i == at.segment && tc <= at.t + 1e-9 && std::hypot(b.x - a.x, b.y - a.y) > kMinSegmentM) {
        (*covered)[grid.Index(c.row, c.col)] = 1;  // already behind the robot
      } else {
        leg.cells.push_back(c);
      }
    }
    legs.push_back(std::move(leg));
  }
  return legs;
}

bool NewlyClosed(const Grid& old_drive, const Grid& drive, int r, int c) {
  if (!drive.InBounds(r, c)) return true;
  return old_drive.IsFree(r, c) && !drive.IsFree(r, c);
}

absl::StatusOr<bool> AppendRoute(const Grid& drive, Point2 from, const Pose2& to,
                                 const StopToken& stop, std::vector<Waypoint>* path) {
  if (std::hypot(from.x - to.x, from.y - to.y) < kMinSegmentM) return true;
  ASSIGN_OR_RETURN(CellIndex a, JoinCell(drive, Pose2{from.x, from.y, 0}, "start"));
  ASSIGN_OR_RETURN(CellIndex b, JoinCell(drive, to, "end"));
  AnyAngleSearch search(drive);
  if (!search.Run(a, stop)) return false;
  std::vector<Point2> pts;
  for (const CellIndex& cell : search.PathTo(b)) pts.push_back(drive.CellCenter(cell));
  pts.push_back({to.x, to.y});
  Point2 at = from;
  for (const Point2& p : pts) {
    if (std::hypot(p.x - at.x, p.y - at.y) < kMinSegmentM) continue;
    path->push_back({p.x, p.y, std::atan2(p.y - at.y, p.x - at.x), SegmentKind::kTransition, -1});
    at = p;
  }
  return true;
}

Walk GreedyWalk(const Grid& old_drive, const Grid& drive, const std::vector<Leg>& legs,
                Point2 robot, double heading) {
  auto closed = [&](int r, int c) { return NewlyClosed(old_drive, drive, r, c); };
  Walk w;
  w.swept.assign(static_cast<size_t>(drive.size()), 0);
  w.path.push_back({robot.x, robot.y, heading, SegmentKind::kStart, -1});
  Point2 cursor = robot;
  double cur_heading = heading;
  auto emit = [&](Point2 to, SegmentKind kind, std::vector<CellIndex> cells, double axis,
                  int tag = -1) {
    const double dx = to.x - cursor.x, dy = to.y - cursor.y;
    const bool moves = std::hypot(dx, dy) >= kMinSegmentM;
    if (kind == SegmentKind::kCoverage) {
      cells.erase(
          std::remove_if(cells.begin(), cells.end(), [&](CellIndex c) { return !drive.IsFree(c); }),
          cells.end());
      if (cells.empty() && !moves) return;
      if (cells.empty()) kind = SegmentKind::kTransition;
    } else if (!moves) {
      return;
    }
    cur_heading = moves ? std::atan2(dy, dx) : axis;
    cursor = to;
    w.path.push_back({to.x, to.y, cur_heading, kind, kind == SegmentKind::kCoverage ? tag : -1});
    if (kind == SegmentKind::kCoverage) {
      for (const CellIndex& c : cells) w.swept[drive.Index(c.row, c.col)] = 1;
      w.sweeps.push_back({static_cast<int>(w.path.size()) - 1, std::move(cells)});
    }
  };
  auto part_cells = [&](const Leg& leg, double t0, double t1) {
    std::vector<CellIndex> out;
    for (const CellIndex& c : leg.cells) {
      const double tc = Param(leg.a, leg.b, drive.CellCenter(c));
      if (tc >= t0 - 1e-9 && tc <= t1 + 1e-9) out.push_back(c);
    }
    return out;
  };
  auto join = [&](Point2 p) {
    absl::StatusOr<CellIndex> c = JoinCell(drive, Pose2{p.x, p.y, 0}, "point");
    return c.ok() ? *c : drive.CellAt(p);
  };
  AnyAngleSearch search(drive);
  // A detour that rejoins a station leg is part of that leg (battery plans:
  // the trip to or from the station goes on, only around the obstacle).
  auto detour = [&](Point2 from, Point2 to, SegmentKind rejoined) {
    const SegmentKind kind =
        rejoined == SegmentKind::kToStation || rejoined == SegmentKind::kFromStation
            ? rejoined
            : SegmentKind::kTransition;
    const CellIndex a = join(from), b = join(to);
    search.Run(a, StopToken());
    std::vector<CellIndex> corners = search.PathTo(b);
    emit(drive.CellCenter(a), kind, {}, cur_heading);
    for (const CellIndex& c : corners) emit(drive.CellCenter(c), kind, {}, cur_heading);
    emit(to, kind, {}, cur_heading);
  };
  const double step = drive.cell_size() / 8.0;
  bool blocked = false;
  Point2 last_free = robot;
  for (size_t j = 0; j < legs.size(); ++j) {
    const Leg& leg = legs[j];
    const double len = std::hypot(leg.b.x - leg.a.x, leg.b.y - leg.a.y);
    const double axis =
        len >= kMinSegmentM ? std::atan2(leg.b.y - leg.a.y, leg.b.x - leg.a.x) : cur_heading;
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    double run_start = 0.0, last_free_t = 0.0;
    Point2 prev = leg.a;
    for (int s = 0; s <= n; ++s) {
      const double t = static_cast<double>(s) / n;
      const Point2 p = Lerp(leg.a, leg.b, t);
      const CellIndex cell = drive.CellAt(p);
      const bool open = !closed(cell.row, cell.col);
      // Exact: the piece since the last sample must not touch a closed cell
      // (a segment may clip a cell or pass a corner between two samples).
      const bool free = open && (s == 0 || !SegmentTouches(drive, prev, p, closed));
      prev = p;
      if (!blocked) {
        if (free) {
          last_free_t = t;
          continue;
        }
        // Entering a blocked stretch: drive up to the last free point.
        emit(Lerp(leg.a, leg.b, last_free_t), leg.kind, part_cells(leg, run_start, last_free_t),
             axis);
        last_free = cursor;
        w.at_encounter.push_back(
            {w.path.size(), w.sweeps.size(), cursor, cur_heading, static_cast<int>(j)});
        blocked = true;
      } else if (open && drive.IsFree(cell)) {
        // Out of it (drive' is one component: every free cell is reachable).
        detour(last_free, p, leg.kind);
        blocked = false;
        run_start = last_free_t = t;
      }
    }
    if (!blocked) {
      // A whole old coverage segment driven unchanged keeps its rank tag.
      const bool unchanged = leg.whole && run_start <= 0.0;
      emit(leg.b, leg.kind, part_cells(leg, run_start, 1.0), axis, unchanged ? leg.tag : -1);
    }
  }
  w.encounters = static_cast<int>(w.at_encounter.size());
  w.end = cursor;
  w.end_heading = cur_heading;
  w.end_leg = static_cast<int>(legs.size()) - 1;
  return w;
}

Walk Walk::Prefix(int k, const Grid& drive) const {
  const Snapshot& at = at_encounter[k];
  Walk p;
  p.path.assign(path.begin(), path.begin() + static_cast<std::ptrdiff_t>(at.path_size));
  p.sweeps.assign(sweeps.begin(), sweeps.begin() + static_cast<std::ptrdiff_t>(at.sweeps_size));
  p.swept.assign(static_cast<size_t>(drive.size()), 0);
  for (const CoverageSweep& s : p.sweeps) {
    for (const CellIndex& c : s.cells) p.swept[drive.Index(c.row, c.col)] = 1;
  }
  p.encounters = k;
  p.stopped = true;
  p.end = at.end;
  p.end_heading = at.heading;
  p.end_leg = at.leg;
  return p;
}

}  // namespace covplan::replan_internal
