// Test helpers for STC: grids built from random coarse shapes, and a plan of
// the "stc" planner straight on a grid (no map), the drive grid also the
// cover grid.
#ifndef COVPLAN_TESTS_STC_STC_TEST_UTIL_H_
#define COVPLAN_TESTS_STC_STC_TEST_UTIL_H_

#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/engine/engine.h"
#include "planner/stc/stc_planner.h"
#include "planner/tour/grid_paths.h"

namespace covplan::testing {

// A connected random shape of `n_coarse` coarse cells (grown from the
// centre of a rows x cols coarse board), drawn at two tool cells per coarse
// cell, shifted by `shift` tool cells (blocked margin) on both axes.
inline Grid RandomCoarseShape(int rows, int cols, int n_coarse, uint32_t seed, int shift = 0,
                              double cell = 1.0) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> in(static_cast<size_t>(rows) * cols, 0);
  std::vector<int> frontier = {(rows / 2) * cols + cols / 2};
  in[frontier[0]] = 1;
  int count = 1;
  while (count < n_coarse && !frontier.empty()) {
    const int pick =
        std::uniform_int_distribution<int>(0, static_cast<int>(frontier.size()) - 1)(rng);
    const int id = frontier[pick];
    const int dr[4] = {0, 1, 0, -1}, dc[4] = {1, 0, -1, 0};
    const int d = std::uniform_int_distribution<int>(0, 3)(rng);
    const int r = id / cols + dr[d], c = id % cols + dc[d];
    if (r < 0 || c < 0 || r >= rows || c >= cols || in[r * cols + c]) continue;
    in[r * cols + c] = 1;
    frontier.push_back(r * cols + c);
    ++count;
  }
  const int R = 2 * rows + shift + 1, C = 2 * cols + shift + 1;
  std::vector<uint8_t> free(static_cast<size_t>(R) * C, 0);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (!in[r * cols + c]) continue;
      for (int k = 0; k < 4; ++k) free[(2 * r + shift + k / 2) * C + 2 * c + shift + k % 2] = 1;
    }
  }
  return Grid(R, C, cell, {0.0, 0.0}, std::move(free));
}

// `grid` with the free cells outside its largest 4-connected component closed.
inline Grid LargestComponent(const Grid& grid) {
  int32_t n = 0;
  const std::vector<int32_t> comp = FreeComponents(grid, &n);
  std::vector<int64_t> size(n, 0);
  for (int32_t c : comp) {
    if (c >= 0) ++size[c];
  }
  int32_t best = 0;
  for (int32_t c = 1; c < n; ++c) {
    if (size[c] > size[best]) best = c;
  }
  std::vector<uint8_t> free(grid.size(), 0);
  for (int64_t i = 0; i < grid.size(); ++i) free[i] = comp[i] == best;
  return grid.WithFreeFlags(std::move(free));
}

// Random free cells (probability p), largest component kept.
inline Grid RandomConnectedGrid(int rows, int cols, double p, uint32_t seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution free(p);
  std::vector<uint8_t> cells(static_cast<size_t>(rows) * cols);
  for (auto& c : cells) c = free(rng);
  return LargestComponent(Grid(rows, cols, 1.0, {0.0, 0.0}, std::move(cells)));
}

// The "stc" planner on `grid` (drive = cover), as the engine would call it,
// with the engine's path statistics filled.
inline absl::StatusOr<CoveragePlan> PlanStcOnGrid(const Grid& grid, const StcOptions& options,
                                                  RobotModel robot = {}) {
  auto area = std::make_shared<CoverageArea>();
  area->drive = std::make_shared<const Grid>(grid);
  area->cover = area->drive;
  area->cover_cells = grid.CountFree();
  CommonOptions common;
  robot.tool_width_m = grid.cell_size();
  common.robot = robot;
  PlanContext ctx;
  ctx.common = &common;
  ctx.options = &options;
  ctx.area = area;
  StcPlanner planner;
  absl::StatusOr<CoveragePlan> plan = planner.Plan(ctx);
  if (!plan.ok()) return plan;
  const PlanStats path = ComputePathStats(plan->path, robot);
  plan->stats.coverage_length_m = path.coverage_length_m;
  plan->stats.transition_length_m = path.transition_length_m;
  plan->stats.num_turns = path.num_turns;
  return plan;
}

// Times the path's centre line enters each cell (the start cell counts once
// at the start), over waypoints 1..last. Axis-parallel unit-cell paths only.
inline std::vector<int> CellEntries(const Grid& grid, const std::vector<Waypoint>& path,
                                    size_t last) {
  std::vector<int> entries(grid.size(), 0);
  if (path.empty()) return entries;
  CellIndex prev = grid.CellAt({path[0].x, path[0].y});
  if (grid.InBounds(prev.row, prev.col)) ++entries[grid.Index(prev.row, prev.col)];
  for (size_t i = 1; i <= last && i < path.size(); ++i) {
    const double len = std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.05 * grid.cell_size()))));
    for (int k = 1; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const CellIndex c = grid.CellAt({path[i - 1].x + t * (path[i].x - path[i - 1].x),
                                       path[i - 1].y + t * (path[i].y - path[i - 1].y)});
      if (c != prev && grid.InBounds(c.row, c.col)) ++entries[grid.Index(c.row, c.col)];
      prev = c;
    }
  }
  return entries;
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_STC_STC_TEST_UTIL_H_
