// RAII wrapper around a GLPK linear (or mixed-integer) program. The only
// unit that includes glpk.h.
//
//   LinearProgram lp;
//   int x = lp.AddColumn(0, 1, /*objective=*/1.0);
//   lp.AddRow(1.0, LinearProgram::kInf, {{x, 1.0}});
//   absl::StatusOr<LpSolution> sol = lp.Solve({.time_limit_s = 5});
//
// GLPK's terminal output is silenced. Every GLPK return code maps to an
// absl::Status. GLPK keeps a per-thread environment; it is freed with
// glp_free_env() when the last LinearProgram of a thread is destroyed, so
// worker threads do not leak.
// Thread-safety: an instance must be used by one thread; distinct instances
// on distinct threads are independent. Not movable across threads.
#ifndef COVPLAN_PLANNER_LP_GLPK_PROBLEM_H_
#define COVPLAN_PLANNER_LP_GLPK_PROBLEM_H_

#include <limits>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"

namespace covplan {

struct LpSolveOptions {
  double time_limit_s = 60.0;  // GLPK cannot be interrupted: always bounded
  bool integer = false;        // solve as MIP (branch and bound) after the LP
  bool presolve = true;
};

struct LpSolution {
  double objective = 0.0;
  std::vector<double> values;  // per column
  bool integral = false;       // every integer column within 1e-6 of an integer
};

class LinearProgram {
 public:
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  LinearProgram();
  ~LinearProgram();
  LinearProgram(const LinearProgram&) = delete;
  LinearProgram& operator=(const LinearProgram&) = delete;

  // Returns the 0-based column index. Infinite bounds are allowed.
  int AddColumn(double lower, double upper, double objective, bool integer = false);
  // Adds lower <= sum(coeff * x[col]) <= upper.
  void AddRow(double lower, double upper, const std::vector<std::pair<int, double>>& terms);
  int num_columns() const { return num_cols_; }
  int num_rows() const { return static_cast<int>(row_lower_.size()); }

  // Minimises. DeadlineExceeded on time limit, FailedPrecondition when
  // infeasible/unbounded, Internal for numerical failures.
  absl::StatusOr<LpSolution> Solve(const LpSolveOptions& options);

 private:
  void* prob_;  // glp_prob*
  int num_cols_ = 0;
  std::vector<double> row_lower_, row_upper_;
  std::vector<int> ia_, ja_;  // 1-based triplets, GLPK style (index 0 unused)
  std::vector<double> ar_;
  std::vector<bool> integer_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_LP_GLPK_PROBLEM_H_
