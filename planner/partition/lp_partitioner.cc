#include "planner/partition/lp_partitioner.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/lp/glpk_problem.h"

namespace covplan {

absl::StatusOr<RankPartition> LpPartitioner::Partition(const Grid& grid,
                                                       const StopToken& stop) const {
  if (grid.size() == 0) return absl::InvalidArgumentError("grid is empty");
  LinearProgram lp;
  struct Vars {
    int xh, xv;
  };
  std::vector<Vars> var(grid.size(), Vars{-1, -1});
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (!grid.free_flags()[i]) continue;
    var[i].xh = lp.AddColumn(0.0, 1.0, 0.0, /*integer=*/true);
    var[i].xv = lp.AddColumn(0.0, 1.0, 0.0, /*integer=*/true);
    lp.AddRow(1.0, 1.0, {{var[i].xh, 1.0}, {var[i].xv, 1.0}});  // (3.8)
  }
  if (lp.num_columns() == 0) return absl::InvalidArgumentError("grid has no free cell");
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!grid.IsFree(r, c)) continue;
      const Vars v = var[grid.Index(r, c)];
      // (3.6): y_h - x_h + x_h(left) >= 0
      const int yh = lp.AddColumn(0.0, LinearProgram::kInf, 1.0);
      std::vector<std::pair<int, double>> row_h = {{yh, 1.0}, {v.xh, -1.0}};
      if (grid.LeftLinked(r, c)) row_h.push_back({var[grid.Index(r, c - 1)].xh, 1.0});
      lp.AddRow(0.0, LinearProgram::kInf, row_h);
      // (3.7): y_v - x_v + x_v(below) >= 0
      const int yv = lp.AddColumn(0.0, LinearProgram::kInf, 1.0);
      std::vector<std::pair<int, double>> row_v = {{yv, 1.0}, {v.xv, -1.0}};
      if (grid.BelowLinked(r, c)) row_v.push_back({var[grid.Index(r - 1, c)].xv, 1.0});
      lp.AddRow(0.0, LinearProgram::kInf, row_v);
    }
  }
  LpSolveOptions options;
  options.integer = true;  // only used if the relaxation were ever fractional
  options.time_limit_s = time_limit_s_;
  if (stop.has_deadline()) {
    options.time_limit_s = std::min(options.time_limit_s, absl::ToDoubleSeconds(stop.remaining()));
  }
  if (stop.ShouldStop() || options.time_limit_s <= 0) {
    return absl::DeadlineExceededError("no time left for the partition LP");
  }
  absl::StatusOr<LpSolution> sol = lp.Solve(options);
  if (!sol.ok()) return sol.status();

  RankPartition result;
  result.orientation.assign(grid.size(), 1);
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (var[i].xh >= 0 && sol->values[var[i].xh] > 0.5) result.orientation[i] = 0;
  }
  result.ranks = RanksFromOrientation(grid, result.orientation);
  result.objective = sol->objective;
  if (std::abs(sol->objective - static_cast<double>(result.ranks.size())) > 1e-6) {
    return absl::InternalError(absl::StrFormat("LP optimum %g disagrees with %d ranks",
                                               sol->objective, result.ranks.size()));
  }
  return result;
}

}  // namespace covplan
