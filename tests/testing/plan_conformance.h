// The conformance checks every coverage planner must pass, proven from the
// path and its sweeps: every cell to cover swept, the path never enters a
// blocked cell, a barrier or a no-go polygon, statistics consistent with the
// path. Independent of the planner's own geometry code: segments are checked
// by dense sampling and a point-in-polygon test of their own.
#ifndef COVPLAN_TESTS_TESTING_PLAN_CONFORMANCE_H_
#define COVPLAN_TESTS_TESTING_PLAN_CONFORMANCE_H_

#include <cmath>
#include <string>
#include <vector>

#include <algorithm>
#include "absl/strings/str_format.h"

#include "planner/assembly/plan_coverage.h"
#include "planner/engine/engine.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/plan/coverage_plan.h"
#include "tests/testing/grid_fixtures.h"

namespace covplan::testing {

// First point (sampled every 1 % of a cell) of the path outside free cells,
// or the first move between cells across a thin-wall barrier.
// "" when no point of the path's centre line (sampled every 1/20 pixel, from
// waypoint `first` on) lies inside an obstacle of `map`: the cell grid may
// call a cell with a table in it free, the drive line must still miss it.
// "Inside" means in the interior of the union of non-free pixels (off-map
// counts as non-free): a line may touch an obstacle's face or corner, not
// enter it.
inline std::string CheckPathAvoidsMapObstacles(const OccupancyMap& map,
                                               const std::vector<Waypoint>& path,
                                               size_t first = 0) {
  const double res = map.resolution();
  auto blocked = [&](double x, double y) {
    const int col = static_cast<int>(std::floor(x)), row = static_cast<int>(std::floor(y));
    return col < 0 || row < 0 || col >= map.width() || row >= map.height() || !map.IsFree(row, col);
  };
  constexpr double kNudge = 1e-6;  // pixels
  for (size_t i = first + 1; i < path.size(); ++i) {
    const Waypoint& a = path[i - 1];
    const Waypoint& b = path[i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (res / 20.0))));
    for (int k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const double x = (a.x + t * (b.x - a.x) - map.origin().x) / res;
      const double y = (a.y + t * (b.y - a.y) - map.origin().y) / res;
      if (blocked(x - kNudge, y - kNudge) && blocked(x + kNudge, y - kNudge) &&
          blocked(x - kNudge, y + kNudge) && blocked(x + kNudge, y + kNudge)) {
        return absl::StrFormat(
            "segment %d (%s) enters an obstacle at pixel (%d, %d), (%.3f, %.3f) m", i,
            b.kind == SegmentKind::kCoverage ? "coverage" : "transition",
            static_cast<int>(std::floor(y)), static_cast<int>(std::floor(x)), a.x + t * (b.x - a.x),
            a.y + t * (b.y - a.y));
      }
    }
  }
  return "";
}

// `may_leave_start_cell`: the path may start in a blocked cell (a dock, or a
// robot whose own cell was just reported blocked) and leave it; it may never
// come back to it.
inline std::string CheckPathStaysFree(const Grid& grid, const std::vector<Waypoint>& path,
                                      bool may_leave_start_cell = false) {
  CellIndex prev{-1, -1};
  const CellIndex start = path.empty() ? CellIndex{-1, -1} : grid.CellAt({path[0].x, path[0].y});
  bool leaving = may_leave_start_cell && !path.empty() && !grid.IsFree(start);
  for (size_t i = 0; i < path.size(); ++i) {
    const Waypoint& b = path[i];
    const Waypoint& a = i == 0 ? b : path[i - 1];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.01 * grid.cell_size()))));
    for (int k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const Point2 p{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
      const CellIndex cell = grid.CellAt(p);
      if (leaving && cell == start) continue;
      leaving = false;
      if (!grid.IsFree(cell)) {
        return absl::StrFormat("segment %d passes (%.3f, %.3f) outside free cells", i, p.x, p.y);
      }
      if (prev.row >= 0 && cell != prev) {
        const int dr = cell.row - prev.row, dc = cell.col - prev.col;
        bool ok = false;
        if (std::abs(dr) + std::abs(dc) == 1) {
          ok = grid.Passable(prev.row, prev.col, dr, dc);
        } else if (std::abs(dr) == 1 && std::abs(dc) == 1) {
          ok = (grid.Passable(prev.row, prev.col, 0, dc) &&
                grid.Passable(prev.row, prev.col + dc, dr, 0)) ||
               (grid.Passable(prev.row, prev.col, dr, 0) &&
                grid.Passable(prev.row + dr, prev.col, 0, dc));
        }
        if (!ok) {
          return absl::StrFormat("segment %d crosses a barrier near (%.3f, %.3f)", i, p.x, p.y);
        }
      }
      prev = cell;
    }
  }
  return "";
}

// Strictly inside `ring` (even-odd ray casting; points on the boundary may
// go either way, so callers keep a margin). Independent of Boost.Geometry.
inline bool InsideRing(const std::vector<Point2>& ring, double x, double y) {
  bool in = false;
  for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Point2& a = ring[i];
    const Point2& b = ring[j];
    if ((a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x) in = !in;
  }
  return in;
}
inline bool InsidePolygon(const PolygonInput& p, double x, double y) {
  if (!InsideRing(p.outer, x, y)) return false;
  for (const auto& hole : p.holes) {
    if (InsideRing(hole, x, y)) return false;
  }
  return true;
}
// Distance from (x, y) to the polygon's boundary.
inline double BoundaryDistance(const PolygonInput& p, double x, double y) {
  double best = 1e300;
  auto ring = [&](const std::vector<Point2>& r) {
    for (size_t i = 1; i < r.size(); ++i) {
      const double dx = r[i].x - r[i - 1].x, dy = r[i].y - r[i - 1].y;
      const double len2 = dx * dx + dy * dy;
      double t = len2 > 0 ? ((x - r[i - 1].x) * dx + (y - r[i - 1].y) * dy) / len2 : 0.0;
      t = std::clamp(t, 0.0, 1.0);
      best = std::min(best, std::hypot(x - (r[i - 1].x + t * dx), y - (r[i - 1].y + t * dy)));
    }
  };
  ring(p.outer);
  for (const auto& h : p.holes) ring(h);
  return best;
}

// "" when no point of the path (sampled every 1 mm) lies inside a no-go
// polygon by more than 1e-6 m; else the first offending segment.
inline std::string CheckPathAvoidsZones(const std::vector<Waypoint>& path,
                                        const std::vector<PolygonInput>& no_go) {
  for (size_t i = 1; i < path.size(); ++i) {
    const Waypoint& a = path[i - 1];
    const Waypoint& b = path[i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / 1e-3)));
    for (int k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const double x = a.x + t * (b.x - a.x), y = a.y + t * (b.y - a.y);
      for (size_t z = 0; z < no_go.size(); ++z) {
        if (InsidePolygon(no_go[z], x, y) && BoundaryDistance(no_go[z], x, y) > 1e-6) {
          return absl::StrFormat("segment %d enters no-go zone %d at (%.4f, %.4f)", i, z, x, y);
        }
      }
    }
  }
  return "";
}

// The conformance every registered planner must pass, proven from the path:
//  - the path never leaves the drive grid's free cells or crosses a barrier;
//  - every coverage segment has a sweep, and every swept cell is a free
//    drive cell whose centre the segment passes through;
//  - every cell to cover is swept;
//  - the statistics agree with the path;
//  - no segment enters a no-go polygon (dense sampling, own point test).
inline std::string CheckPlanConformance(const CoveragePlan& plan, const CoverageArea& area,
                                        const RobotModel& robot,
                                        const std::vector<PolygonInput>& no_go = {}) {
  const Grid& drive = *area.drive;
  const Grid& cover = *area.cover;
  if (plan.grid.get() != area.drive.get()) return "plan grid is not the area's drive grid";
  std::string err = CheckPathStaysFree(drive, plan.path, /*may_leave_start_cell=*/true);
  if (!err.empty()) return err;
  err = CheckPathAvoidsZones(plan.path, no_go);
  if (!err.empty()) return err;
  int coverage_segments = 0;
  for (size_t i = 1; i < plan.path.size(); ++i)
    coverage_segments += plan.path[i].kind == SegmentKind::kCoverage;
  if (static_cast<int>(plan.sweeps.size()) != coverage_segments) {
    return absl::StrFormat("%d sweeps for %d coverage segments", plan.sweeps.size(),
                           coverage_segments);
  }
  std::vector<uint8_t> swept(drive.size(), 0);
  int last = 0;
  for (const CoverageSweep& s : plan.sweeps) {
    if (s.waypoint <= last || s.waypoint >= static_cast<int>(plan.path.size()) ||
        plan.path[s.waypoint].kind != SegmentKind::kCoverage) {
      return absl::StrFormat("sweep at waypoint %d is not a coverage segment in path order",
                             s.waypoint);
    }
    last = s.waypoint;
    const Waypoint& a = plan.path[s.waypoint - 1];
    const Waypoint& b = plan.path[s.waypoint];
    for (const CellIndex& c : s.cells) {
      if (!drive.IsFree(c)) {
        return absl::StrFormat("sweep %d sweeps blocked cell (%d, %d)", s.waypoint, c.row, c.col);
      }
      const Point2 m = drive.CellCenter(c);
      const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
      const double t =
          len2 > 0 ? std::clamp(((m.x - a.x) * dx + (m.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
      if (std::hypot(m.x - (a.x + t * dx), m.y - (a.y + t * dy)) > 1e-6) {
        return absl::StrFormat("sweep %d claims cell (%d, %d) that its segment misses", s.waypoint,
                               c.row, c.col);
      }
      swept[drive.Index(c.row, c.col)] = 1;
    }
  }
  int64_t covered = 0, to_cover = 0;
  for (int64_t i = 0; i < drive.size(); ++i) {
    covered += swept[i];
    if (!cover.free_flags()[i]) continue;
    ++to_cover;
    if (!swept[i]) {
      const CellIndex c = drive.FromIndex(i);
      return absl::StrFormat("cell (%d, %d) to cover is never swept", c.row, c.col);
    }
  }
  const PlanStats s = ComputePathStats(plan.path, robot);
  auto close = [](double a, double b) {
    return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b));
  };
  if (s.num_turns != plan.stats.num_turns) return "num_turns inconsistent with the path";
  if (!close(s.coverage_length_m, plan.stats.coverage_length_m))
    return "coverage length inconsistent";
  if (!close(s.transition_length_m, plan.stats.transition_length_m))
    return "transition length inconsistent";
  if (!close(s.estimated_duration_s, plan.stats.estimated_duration_s))
    return "duration inconsistent";
  if (plan.stats.covered_cells != covered) return "covered_cells inconsistent with the sweeps";
  if (plan.stats.free_cells != to_cover) return "free_cells is not the number of cells to cover";
  return "";
}

// OARP's own invariants on top: the ranks partition the cells to cover
// exactly, and each rank is driven once, end to end, by one coverage segment.
inline std::string CheckOarpDetail(const CoveragePlan& plan, const Grid& cover) {
  const OarpDetail* oarp = plan.detail_as<OarpDetail>();
  if (oarp == nullptr) return "plan has no OARP detail";
  std::string err = CheckExactCover(cover, oarp->ranks);
  if (!err.empty()) return err;
  const Grid& grid = *plan.grid;
  std::vector<int> driven(oarp->ranks.size(), 0);
  for (size_t i = 1; i < plan.path.size(); ++i) {
    const Waypoint& w = plan.path[i];
    if (w.kind != SegmentKind::kCoverage) continue;
    if (w.rank < 0 || w.rank >= static_cast<int>(oarp->ranks.size()))
      return "coverage segment without rank";
    const Rank& r = oarp->ranks[w.rank];
    const Point2 f = grid.CellCenter(r.first), l = grid.CellCenter(r.last);
    const Waypoint& prev = plan.path[i - 1];
    auto near = [](double x, double y, Point2 p) { return std::hypot(x - p.x, y - p.y) < 1e-6; };
    const bool fwd = near(prev.x, prev.y, f) && near(w.x, w.y, l);
    const bool bwd = near(prev.x, prev.y, l) && near(w.x, w.y, f);
    if (!fwd && !bwd)
      return absl::StrFormat("coverage segment %d does not run along rank %d", i, w.rank);
    ++driven[w.rank];
  }
  for (size_t k = 0; k < driven.size(); ++k) {
    if (driven[k] != 1) return absl::StrFormat("rank %d driven %d times", k, driven[k]);
  }
  if (plan.stats.num_ranks != static_cast<int64_t>(oarp->ranks.size()))
    return "num_ranks inconsistent";
  return "";
}

// Both of the above for an engine result.
inline std::string CheckOarpConformance(const EngineResult& r, const RobotModel& robot,
                                        const std::vector<PolygonInput>& no_go = {}) {
  std::string err = CheckPlanConformance(r.plan, *r.area, robot, no_go);
  if (!err.empty()) return err;
  return CheckOarpDetail(r.plan, *r.area->cover);
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_PLAN_CONFORMANCE_H_
