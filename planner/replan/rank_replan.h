// RANK-REPLAN (thesis §4.4, algorithms.md §4): re-partition the cells still to
// cover into straight ranks after new obstacles appear, minimising the number
// of ranks while allowing at most a budget m̄ of ranks that are not in the old
// plan (each new rank costs transition and GTSP time before the robot reaches
// the obstacle).
//
// Two integer programs over the same base ILP-0 (orientation x, endpoint
// indicators y), both solved with GLPK:
// - kIlp1: matches every left end with its right end (z_ij per pair of cells of
//   a maximal run), so m_new is exact and the result is optimal for the budget.
//   O(Σ run_length²) variables.
// - kIlp2: bounds m_new by added endpoints α plus half the extended endpoints β
//   (Lemma 4.2); O(n) variables, pessimistic (may need a larger budget).
// Deviations from the thesis, on purpose (see rank_replan.cc):
// - The thesis' y >= x - x_nb lets a budgeted solve claim phantom ends that
//   "keep" two old ranks while leaving the cells between them uncovered. Here
//   the end before a link and the start after it share one variable (between
//   equally oriented cells, a rank ends there iff another starts), and y <= x,
//   so every solution is an exact cover.
// - Equalities are eliminated (x_V = 1 - x_H, y from x and the link), about
//   halving the program. Both ILPs keep their meaning; m counts ranks exactly.
// A result may split a straight line into two touching ranks when that keeps
// two old ranks within the budget; otherwise ranks are maximal runs of equally
// oriented cells, as RanksFromOrientation would give.
//
//   RankReplanInput in;
//   in.cells = &w;                  // W: blocked and covered cells removed
//   in.old_ranks = old_plan.ranks;
//   in.budget = 5;
//   absl::StatusOr<RankReplanResult> r =
//       RankReplan(in, RankReplanMethod::kIlp2, StopToken::WithTimeout(absl::Seconds(2)));
//   if (absl::IsFailedPrecondition(r.status())) { /* greedy detour */ }
//
// GLPK cannot be interrupted: each solve gets the time `stop` has left as its
// limit; a Cancel() is only seen between solves.
// Thread-safety: RankReplan is reentrant (one GLPK problem per call).
#ifndef COVPLAN_PLANNER_REPLAN_RANK_REPLAN_H_
#define COVPLAN_PLANNER_REPLAN_RANK_REPLAN_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"

namespace covplan {

enum class RankReplanMethod { kIlp1, kIlp2 };

struct RankReplanInput {
  // W: its free cells are the cells still to cover; barriers are respected.
  const Grid* cells = nullptr;
  // Ranks of the old plan, on the same grid, pairwise disjoint. Any of them may
  // cross cells no longer in W; only those lying wholly in W can be kept.
  std::vector<Rank> old_ranks;
  // m̄: the most new ranks allowed.
  int64_t budget = kUnlimited;
  static constexpr int64_t kUnlimited = -1;
};

struct RankReplanResult {
  std::vector<Rank> ranks;   // exact cover of W's free cells by straight ranks
  std::vector<bool> is_new;  // per rank: not identical (orientation and ends) to an old rank
  int64_t num_new = 0;       // true count (CountNewRanks), always <= budget
  // ILP-2 only: the bound α + β/2 of the solution (>= num_new); ILP-1: == num_new.
  double new_rank_bound = 0.0;
  bool relaxation_integral = false;  // the LP relaxation was already integral
  bool used_mip = false;             // branch and bound was needed
  int64_t num_columns = 0, num_rows = 0;
  double build_ms = 0.0;  // building the program
  double solve_ms = 0.0;  // GLPK (LP relaxation plus branch and bound, if any)
};

// FailedPrecondition when no partition exists within the budget (for kIlp2:
// none whose bound α + β/2 fits; the caller falls back to greedy detour).
// DeadlineExceeded when `stop` leaves no time or GLPK hits the time it was
// given; Cancelled when `stop` was cancelled. InvalidArgument on bad input:
// null grid, W without a free cell, negative budget other than kUnlimited, an
// old rank that is not straight, leaves the grid, or overlaps another.
absl::StatusOr<RankReplanResult> RankReplan(const RankReplanInput& input, RankReplanMethod method,
                                            const StopToken& stop);

// The size of ILP-1 on W, without building it, for choosing between the two
// programs: 6 per free cell plus one z per pair of cells of every maximal run
// (n (n + 1) / 2 for a run of n), both orientations.
int64_t Ilp1ColumnEstimate(const Grid& w);

// The number of ranks in `ranks` that are not identical to one of `old_ranks`.
int64_t CountNewRanks(const std::vector<Rank>& ranks, const std::vector<Rank>& old_ranks);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_REPLAN_RANK_REPLAN_H_
