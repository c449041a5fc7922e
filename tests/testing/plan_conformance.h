// The conformance checks every coverage planner must pass: every free cell
// covered, the path never enters a blocked cell, statistics consistent with
// the path. Independent of the planner's own geometry code: segments are
// checked by dense sampling.
#ifndef COVPLAN_TESTS_TESTING_PLAN_CONFORMANCE_H_
#define COVPLAN_TESTS_TESTING_PLAN_CONFORMANCE_H_

#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/coverage_planner.h"
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
        return absl::StrFormat("segment %d (%s) enters an obstacle at pixel (%d, %d), (%.3f, %.3f) m",
                               i, b.kind == SegmentKind::kCoverage ? "coverage" : "transition",
                               static_cast<int>(std::floor(y)), static_cast<int>(std::floor(x)),
                               a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
      }
    }
  }
  return "";
}

inline std::string CheckPathStaysFree(const Grid& grid, const std::vector<Waypoint>& path) {
  CellIndex prev{-1, -1};
  for (size_t i = 0; i < path.size(); ++i) {
    const Waypoint& b = path[i];
    const Waypoint& a = i == 0 ? b : path[i - 1];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.01 * grid.cell_size()))));
    for (int k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const Point2 p{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
      const CellIndex cell = grid.CellAt(p);
      if (!grid.IsFree(cell)) {
        return absl::StrFormat("segment %d passes (%.3f, %.3f) outside free cells", i, p.x, p.y);
      }
      if (prev.row >= 0 && cell != prev) {
        const int dr = cell.row - prev.row, dc = cell.col - prev.col;
        bool ok = false;
        if (std::abs(dr) + std::abs(dc) == 1) {
          ok = grid.Passable(prev.row, prev.col, dr, dc);
        } else if (std::abs(dr) == 1 && std::abs(dc) == 1) {
          ok = (grid.Passable(prev.row, prev.col, 0, dc) && grid.Passable(prev.row, prev.col + dc, dr, 0)) ||
               (grid.Passable(prev.row, prev.col, dr, 0) && grid.Passable(prev.row + dr, prev.col, 0, dc));
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

// Every rank driven exactly once, end to end, by one coverage segment; ranks
// cover every free cell exactly once; stats match the path.
inline std::string CheckRankPlanConformance(const CoveragePlan& plan, const RobotModel& robot) {
  const Grid& grid = *plan.grid;
  std::string err = CheckExactCover(grid, plan.ranks);
  if (!err.empty()) return err;
  err = CheckPathStaysFree(grid, plan.path);
  if (!err.empty()) return err;
  std::vector<int> driven(plan.ranks.size(), 0);
  for (size_t i = 1; i < plan.path.size(); ++i) {
    const Waypoint& w = plan.path[i];
    if (w.kind != SegmentKind::kCoverage) continue;
    if (w.rank < 0 || w.rank >= static_cast<int>(plan.ranks.size())) return "coverage segment without rank";
    const Rank& r = plan.ranks[w.rank];
    const Point2 f = grid.CellCenter(r.first), l = grid.CellCenter(r.last);
    const Waypoint& prev = plan.path[i - 1];
    auto near = [](double x, double y, Point2 p) { return std::hypot(x - p.x, y - p.y) < 1e-6; };
    const bool fwd = near(prev.x, prev.y, f) && near(w.x, w.y, l);
    const bool bwd = near(prev.x, prev.y, l) && near(w.x, w.y, f);
    if (!fwd && !bwd) return absl::StrFormat("coverage segment %d does not run along rank %d", i, w.rank);
    ++driven[w.rank];
  }
  for (size_t k = 0; k < driven.size(); ++k) {
    if (driven[k] != 1) return absl::StrFormat("rank %d driven %d times", k, driven[k]);
  }
  const PlanStats s = ComputePathStats(plan.path, robot);
  auto close = [](double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b)); };
  if (s.num_turns != plan.stats.num_turns) return "num_turns inconsistent with the path";
  if (!close(s.coverage_length_m, plan.stats.coverage_length_m)) return "coverage length inconsistent";
  if (!close(s.transition_length_m, plan.stats.transition_length_m)) return "transition length inconsistent";
  if (!close(s.estimated_duration_s, plan.stats.estimated_duration_s)) return "duration inconsistent";
  if (plan.stats.num_ranks != static_cast<int64_t>(plan.ranks.size())) return "num_ranks inconsistent";
  return "";
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_PLAN_CONFORMANCE_H_
