#include "planner/replan/rank_replan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/lp/glpk_problem.h"

namespace covplan {
namespace {

using Terms = std::vector<std::pair<int, double>>;

// Without a deadline GLPK still needs a finite limit.
constexpr double kNoDeadlineSeconds = 1.0e6;

// Endpoint slots of a cell and the neighbour each one looks at.
enum Slot { kLeft = 0, kRight = 1, kBottom = 2, kTop = 3 };
constexpr int kSlotDr[4] = {0, 0, -1, 1};
constexpr int kSlotDc[4] = {-1, 1, 0, 0};
bool IsVerticalSlot(int slot) { return slot >= kBottom; }

using RankKey = std::tuple<int, int, int, int, int>;
RankKey Key(const Rank& r) {
  return {static_cast<int>(r.orientation), r.first.row, r.first.col, r.last.row, r.last.col};
}

double MsSince(absl::Time start) { return absl::ToDoubleMilliseconds(absl::Now() - start); }

// Cells of a straight rank, first to last.
template <typename F>
void ForEachCell(const Rank& r, F f) {
  const bool h = r.orientation == Orientation::kHorizontal;
  for (int i = 0; i < r.NumCells(); ++i) {
    f(h ? r.first.row : r.first.row + i, h ? r.first.col + i : r.first.col);
  }
}

bool LiesIn(const Grid& w, const Rank& r) {
  const bool h = r.orientation == Orientation::kHorizontal;
  if (!w.IsFree(r.first)) return false;
  for (int i = 0; i + 1 < r.NumCells(); ++i) {
    const int row = h ? r.first.row : r.first.row + i, col = h ? r.first.col + i : r.first.col;
    if (!w.Passable(row, col, h ? 0 : 1, h ? 1 : 0)) return false;
  }
  return true;
}

absl::Status ValidateInput(const RankReplanInput& in) {
  if (in.cells == nullptr) return absl::InvalidArgumentError("RankReplanInput.cells is null");
  const Grid& w = *in.cells;
  if (w.CountFree() == 0) {
    return absl::InvalidArgumentError("W has no free cell: nothing to replan");
  }
  if (in.budget < 0 && in.budget != RankReplanInput::kUnlimited) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "budget %d is negative; use a value >= 0 or RankReplanInput::kUnlimited", in.budget));
  }
  std::vector<uint8_t> used(w.size(), 0);
  for (size_t k = 0; k < in.old_ranks.size(); ++k) {
    const Rank& r = in.old_ranks[k];
    const bool h = r.orientation == Orientation::kHorizontal;
    if (h ? r.first.row != r.last.row || r.first.col > r.last.col
          : r.first.col != r.last.col || r.first.row > r.last.row) {
      return absl::InvalidArgumentError(absl::StrFormat("old rank %d is not a straight run", k));
    }
    if (!w.InBounds(r.first.row, r.first.col) || !w.InBounds(r.last.row, r.last.col)) {
      return absl::InvalidArgumentError(absl::StrFormat("old rank %d leaves the grid", k));
    }
    bool overlap = false;
    ForEachCell(r, [&](int row, int col) { overlap |= used[w.Index(row, col)]++ != 0; });
    if (overlap) {
      return absl::InvalidArgumentError(absl::StrFormat("old rank %d overlaps another", k));
    }
  }
  return absl::OkStatus();
}

// Time GLPK may use for the next solve.
absl::StatusOr<double> RemainingSeconds(const StopToken& stop) {
  if (stop.cancelled()) return absl::CancelledError("rank replanning cancelled");
  if (!stop.has_deadline()) return kNoDeadlineSeconds;
  const double s = absl::ToDoubleSeconds(stop.remaining());
  if (s <= 0.0) return absl::DeadlineExceededError("no time left for rank replanning");
  return s;
}

// A linear expression: constant + Σ coeff·column (columns merged, as GLPK
// rejects duplicate entries in a row).
struct Affine {
  double constant = 0.0;
  std::map<int, double> terms;
  void Add(const Affine& a, double scale = 1.0) {
    constant += scale * a.constant;
    for (const auto& [col, coeff] : a.terms) terms[col] += scale * coeff;
  }
  Terms AsTerms() const { return Terms(terms.begin(), terms.end()); }
  double Value(const LpSolution& sol) const {
    double v = constant;
    for (const auto& [col, coeff] : terms) v += coeff * sol.values[col];
    return v;
  }
};

// ILP-0 after eliminating its equalities: one column x = x_H per cell (x_V =
// 1 - x) and one column q per link between neighbours (q = 1: the rank runs
// across the link). Each slot's endpoint indicator is y = x_slot - q_link, or
// y = x_slot at a border or barrier; with q <= x_a, q <= x_b per link this is
// the thesis' y >= x - x_nb (q <= x_nb) plus y <= x (q >= 0), and it ties the
// end on one side of a link to the start on the other, so a rank cannot end
// without the next one starting: no gaps. q = 0 between two cells of the same
// orientation splits their line into two ranks (only ever chosen to keep two
// touching old ranks under a budget). m = ½Σy = |W| - Σq.
struct BaseModel {
  std::vector<int> x;                       // column per grid cell; -1 outside W
  std::vector<std::array<int, 4>> link;     // q column behind each slot; -1 at a border
  Affine X(int64_t cell, int slot) const {  // x_H for L/R, x_V for B/T
    Affine a;
    if (IsVerticalSlot(slot)) a.constant = 1.0;
    a.terms[x[cell]] = IsVerticalSlot(slot) ? -1.0 : 1.0;
    return a;
  }
  Affine Y(int64_t cell, int slot) const {
    Affine a = X(cell, slot);
    if (link[cell][slot] >= 0) a.terms[link[cell][slot]] = -1.0;
    return a;
  }
};

// `y_cost(cell, slot)` is the objective coefficient of each y (constant
// offsets are dropped from the objective).
template <typename F>
BaseModel AddBaseModel(const Grid& w, F y_cost, LinearProgram& lp) {
  BaseModel m;
  m.x.assign(w.size(), -1);
  m.link.assign(w.size(), {-1, -1, -1, -1});
  for (int64_t i = 0; i < w.size(); ++i) {
    if (!w.free_flags()[i]) continue;
    const double cost = y_cost(i, kLeft) + y_cost(i, kRight) - y_cost(i, kBottom) - y_cost(i, kTop);
    m.x[i] = lp.AddColumn(0.0, 1.0, cost, /*integer=*/true);
  }
  for (int r = 0; r < w.rows(); ++r) {
    for (int c = 0; c < w.cols(); ++c) {
      for (const int s : {kRight, kTop}) {  // each link once, from its lower cell
        if (!w.Passable(r, c, kSlotDr[s], kSlotDc[s])) continue;
        const int64_t a = w.Index(r, c), b = w.Index(r + kSlotDr[s], c + kSlotDc[s]);
        const int back = s == kRight ? kLeft : kBottom;
        const int q = lp.AddColumn(0.0, 1.0, -y_cost(a, s) - y_cost(b, back), /*integer=*/true);
        m.link[a][s] = m.link[b][back] = q;
        for (const int64_t cell : {a, b}) {  // q <= x_slot(cell)
          Affine row = m.X(cell, s);
          row.terms[q] = -1.0;
          lp.AddRow(-row.constant, LinearProgram::kInf, row.AsTerms());
        }
      }
    }
  }
  return m;
}

// Calls f(cells) for every maximal run of linked free cells of orientation `o`,
// cells ordered first (lowest col / row) to last.
template <typename F>
void ForEachRun(const Grid& w, Orientation o, F f) {
  const bool h = o == Orientation::kHorizontal;
  const int outer = h ? w.rows() : w.cols(), inner = h ? w.cols() : w.rows();
  std::vector<CellIndex> run;
  for (int a = 0; a < outer; ++a) {
    for (int b = 0; b < inner; ++b) {
      const CellIndex cell = h ? CellIndex{a, b} : CellIndex{b, a};
      if (!w.IsFree(cell)) continue;
      run.push_back(cell);
      if (!w.Passable(cell.row, cell.col, h ? 0 : 1, h ? 1 : 0)) {
        f(run);
        run.clear();
      }
    }
  }
}

struct Built {
  BaseModel base;
  Affine new_ranks;                     // m_new (ILP-1) or α + β/2 (ILP-2)
  std::vector<std::pair<int, Rank>> z;  // ILP-1: column and the rank it stands for
};

// ILP-1: z_ij per pair of cells of each run, Σ_j z_ij = y_start(i),
// Σ_i z_ij = y_end(j); m_new = Σ(1 - z̄)z.
Built BuildIlp1(const Grid& w, const std::set<RankKey>& old_in_w, double eps, LinearProgram& lp) {
  Built b;
  b.base = AddBaseModel(
      w, [](int64_t, int) { return 0.5; }, lp);
  for (Orientation o : {Orientation::kHorizontal, Orientation::kVertical}) {
    const int start_slot = o == Orientation::kHorizontal ? kLeft : kBottom;
    const int end_slot = o == Orientation::kHorizontal ? kRight : kTop;
    ForEachRun(w, o, [&](const std::vector<CellIndex>& run) {
      const int n = static_cast<int>(run.size());
      std::vector<Affine> starts(n), ends(n);
      for (int i = 0; i < n; ++i) {
        for (int j = i; j < n; ++j) {
          const Rank rank{o, run[i], run[j]};
          const bool old = old_in_w.count(Key(rank)) > 0;
          const int z = lp.AddColumn(0.0, 1.0, old ? 0.0 : eps, /*integer=*/true);
          starts[i].terms[z] = 1.0;
          ends[j].terms[z] = 1.0;
          if (!old) b.new_ranks.terms[z] = 1.0;
          b.z.push_back({z, rank});
        }
      }
      for (int i = 0; i < n; ++i) {
        const int64_t cell = w.Index(run[i].row, run[i].col);
        for (auto [row, slot] :
             {std::pair{&starts[i], start_slot}, std::pair{&ends[i], end_slot}}) {
          row->Add(b.base.Y(cell, slot), -1.0);
          lp.AddRow(-row->constant, -row->constant, row->AsTerms());
        }
      }
    });
  }
  return b;
}

// ILP-2: α = Σ(1 - ȳ)y; β = Σ η with η >= ȳ - ȳy + x - 1, which for ȳ = 1 is
// η >= x_slot - y = q_link (an old end the rank now runs across), and 0 for
// ȳ = 0 or at a border, so η exists only at linked old ends.
Built BuildIlp2(const Grid& w, const std::vector<std::array<uint8_t, 4>>& old_end, double eps,
                LinearProgram& lp) {
  Built b;
  b.base = AddBaseModel(
      w, [&](int64_t cell, int slot) { return 0.5 + (old_end[cell][slot] ? 0.0 : eps); }, lp);
  for (int64_t i = 0; i < w.size(); ++i) {
    if (b.base.x[i] < 0) continue;
    for (int s = 0; s < 4; ++s) {
      if (!old_end[i][s]) {
        b.new_ranks.Add(b.base.Y(i, s));
      } else if (const int q = b.base.link[i][s]; q >= 0) {
        const int eta = lp.AddColumn(0.0, 1.0, eps / 2.0, /*integer=*/true);
        lp.AddRow(0.0, LinearProgram::kInf, {{eta, 1.0}, {q, -1.0}});
        b.new_ranks.terms[eta] = 0.5;
      }
    }
  }
  return b;
}

// The ranks of an integral solution: a rank runs across a link iff q = 1.
std::vector<Rank> RanksFromSolution(const Grid& w, const BaseModel& m, const LpSolution& sol) {
  auto across = [&](int64_t cell, int slot) {
    return m.link[cell][slot] >= 0 && sol.values[m.link[cell][slot]] > 0.5;
  };
  std::vector<Rank> ranks;
  for (Orientation o : {Orientation::kHorizontal, Orientation::kVertical}) {
    const bool h = o == Orientation::kHorizontal;
    ForEachRun(w, o, [&](const std::vector<CellIndex>& run) {
      for (size_t i = 0; i < run.size(); ++i) {
        const int64_t cell = w.Index(run[i].row, run[i].col);
        if ((sol.values[m.x[cell]] > 0.5) != h || across(cell, h ? kLeft : kBottom)) continue;
        size_t j = i;
        while (across(w.Index(run[j].row, run[j].col), h ? kRight : kTop)) ++j;
        ranks.push_back({o, run[i], run[j]});
      }
    });
  }
  return ranks;
}

// The LP relaxation first; branch and bound (warm-started from the optimal
// basis) only when it is fractional. Each solve gets the time that is left.
absl::StatusOr<LpSolution> SolveWithin(LinearProgram& lp, const StopToken& stop,
                                       RankReplanResult& out) {
  ASSIGN_OR_RETURN(const double limit, RemainingSeconds(stop));
  const absl::Time start = absl::Now();
  LpSolveOptions options;
  options.time_limit_s = limit;
  options.integer = false;
  absl::StatusOr<LpSolution> sol = lp.Solve(options);
  if (sol.ok() && !sol->integral) {
    absl::StatusOr<double> left = RemainingSeconds(stop);
    if (!left.ok()) {
      sol = left.status();
    } else {
      options.time_limit_s = *left;
      options.integer = true;
      options.presolve = false;  // keep the optimal basis of the relaxation
      out.used_mip = true;
      sol = lp.Solve(options);
    }
  } else if (sol.ok()) {
    out.relaxation_integral = true;
  }
  out.solve_ms = MsSince(start);
  return sol;
}

}  // namespace

int64_t Ilp1ColumnEstimate(const Grid& w) {
  int64_t cols = 6 * w.CountFree();
  for (Orientation o : {Orientation::kHorizontal, Orientation::kVertical}) {
    ForEachRun(w, o, [&](const std::vector<CellIndex>& run) {
      const int64_t n = static_cast<int64_t>(run.size());
      cols += n * (n + 1) / 2;
    });
  }
  return cols;
}

int64_t CountNewRanks(const std::vector<Rank>& ranks, const std::vector<Rank>& old_ranks) {
  std::vector<RankKey> old;
  old.reserve(old_ranks.size());
  for (const Rank& r : old_ranks) old.push_back(Key(r));
  std::sort(old.begin(), old.end());
  int64_t n = 0;
  for (const Rank& r : ranks) n += !std::binary_search(old.begin(), old.end(), Key(r));
  return n;
}

absl::StatusOr<RankReplanResult> RankReplan(const RankReplanInput& input, RankReplanMethod method,
                                            const StopToken& stop) {
  RETURN_IF_ERROR(ValidateInput(input));
  RETURN_IF_ERROR(RemainingSeconds(stop).status());
  const absl::Time start = absl::Now();
  const Grid& w = *input.cells;
  const int64_t n = w.CountFree();
  const bool ilp1 = method == RankReplanMethod::kIlp1;

  // Old plan: ranks that can be kept (ILP-1) and endpoint flags ȳ (ILP-2; ends
  // of cut ranks count too, which keeps Lemma 4.2 and lowers α).
  std::set<RankKey> old_in_w;
  std::vector<std::array<uint8_t, 4>> old_end(w.size(), {0, 0, 0, 0});
  int64_t num_old_end_slots = 0;
  for (const Rank& r : input.old_ranks) {
    if (LiesIn(w, r)) old_in_w.insert(Key(r));
    const bool h = r.orientation == Orientation::kHorizontal;
    for (auto [cell, slot] :
         {std::pair{r.first, h ? kLeft : kBottom}, std::pair{r.last, h ? kRight : kTop}}) {
      if (!w.IsFree(cell)) continue;
      num_old_end_slots += !old_end[w.Index(cell.row, cell.col)][slot];
      old_end[w.Index(cell.row, cell.col)][slot] = 1;
    }
  }

  // Objective m + ε·s with s = m_new (ILP-1) or α + β/2 (ILP-2). m stays
  // minimal when ε·s < 1 for the minimal solutions (Prop. 4.1): s <= m̄ under a
  // budget row, else s <= s_max. A budget of s_max or more is no constraint.
  const int64_t s_max = ilp1 ? n : 2 * n + (num_old_end_slots + 1) / 2;
  const bool limited = input.budget != RankReplanInput::kUnlimited && input.budget < s_max;
  const double eps = 1.0 / (static_cast<double>(limited ? input.budget : s_max) + 1.0);

  LinearProgram lp;
  Built b = ilp1 ? BuildIlp1(w, old_in_w, eps, lp) : BuildIlp2(w, old_end, eps, lp);
  if (limited) {
    lp.AddRow(-LinearProgram::kInf, static_cast<double>(input.budget) - b.new_ranks.constant,
              b.new_ranks.AsTerms());
  }
  RankReplanResult out;
  out.num_columns = lp.num_columns();
  out.num_rows = lp.num_rows();
  out.build_ms = MsSince(start);

  absl::StatusOr<LpSolution> sol = SolveWithin(lp, stop, out);
  if (absl::IsFailedPrecondition(sol.status())) {
    return absl::FailedPreconditionError(
        absl::StrFormat("%s: no rank partition of W within a budget of %d new ranks (%s)",
                        ilp1 ? "ILP-1" : "ILP-2", input.budget, sol.status().message()));
  }
  if (!sol.ok()) return sol.status();

  out.ranks = RanksFromSolution(w, b.base, *sol);
  std::set<RankKey> old_keys;
  for (const Rank& r : input.old_ranks) old_keys.insert(Key(r));
  out.is_new.reserve(out.ranks.size());
  for (const Rank& r : out.ranks) {
    out.is_new.push_back(old_keys.count(Key(r)) == 0);
    out.num_new += out.is_new.back();
  }
  out.new_rank_bound = b.new_ranks.Value(*sol);
  if (ilp1) {  // Lemma 4.1: the matched pairs are exactly the ranks.
    std::set<RankKey> matched, induced;
    for (const auto& [col, rank] : b.z) {
      if (sol->values[col] > 0.5) matched.insert(Key(rank));
    }
    for (const Rank& r : out.ranks) induced.insert(Key(r));
    if (matched != induced) {
      return absl::InternalError("ILP-1: endpoint matching disagrees with the ranks of x and q");
    }
  }
  if (ilp1 && std::abs(out.new_rank_bound - static_cast<double>(out.num_new)) > 1e-6) {
    return absl::InternalError("ILP-1: m_new of the matching disagrees with the new ranks");
  }
  if (static_cast<double>(out.num_new) > out.new_rank_bound + 1e-6 ||
      (input.budget != RankReplanInput::kUnlimited && out.num_new > input.budget)) {
    return absl::InternalError(absl::StrFormat("%d new ranks exceed the bound %g / budget %d",
                                               out.num_new, out.new_rank_bound, input.budget));
  }
  return out;
}

}  // namespace covplan
