#include "planner/energy/charge_split.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"

namespace covplan {

double CycleEnergy(const SplitProblem& p, int first, int last) {
  double e = p.out[first] + p.back[last];
  for (int k = first; k <= last; ++k) {
    e += p.work[k];
    if (k < last) e += p.link[k];
  }
  return e;
}

absl::StatusOr<SplitResult> SplitTour(const SplitProblem& p, double budget) {
  const int n = p.size();
  if (n == 0) return SplitResult{};
  if (static_cast<int>(p.out.size()) != n || static_cast<int>(p.back.size()) != n ||
      static_cast<int>(p.link.size()) != n - 1 ||
      (!p.break_after.empty() && static_cast<int>(p.break_after.size()) != n)) {
    return absl::InvalidArgumentError(
        "split problem: out, back, link and break_after sizes disagree");
  }
  for (const std::vector<double>* v : {&p.out, &p.work, &p.link, &p.back}) {
    for (double x : *v) {
      if (!std::isfinite(x) || x < 0.0)
        return absl::InvalidArgumentError("split problem: energies must be finite and >= 0");
    }
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // best[b]: least energy of a split of pieces 0..b-1 ending at break b.
  std::vector<double> best(n + 1, kInf);
  std::vector<int> from(n + 1, -1);
  best[0] = 0.0;
  for (int j = 0; j < n; ++j) {
    if (!p.BreakAfter(j)) continue;
    // Walk the cycle's first piece i down from j; the tour part only grows.
    double tour = 0.0;
    for (int i = j; i >= 0; --i) {
      tour += p.work[i] + (i < j ? p.link[i] : 0.0);
      if (tour > budget) break;
      if (i > 0 && !p.BreakAfter(i - 1)) continue;
      if (best[i] == kInf) continue;
      const double cycle = p.out[i] + tour + p.back[j];
      if (cycle > budget) continue;
      if (best[i] + cycle < best[j + 1]) {
        best[j + 1] = best[i] + cycle;
        from[j + 1] = i;
      }
    }
  }
  if (best[n] == kInf) {
    int first_unreached = 0;
    for (int b = 1; b <= n; ++b) {
      if (best[b] < kInf) first_unreached = b;
    }
    return absl::FailedPreconditionError(absl::StrFormat(
        "no split into charge cycles of at most %g exists: piece %d cannot be reached", budget,
        first_unreached));
  }
  SplitResult r;
  r.total = best[n];
  for (int b = n; b > 0; b = from[b]) r.cycles.push_back({from[b], b - 1});
  std::reverse(r.cycles.begin(), r.cycles.end());
  for (const auto& [i, j] : r.cycles) r.energy.push_back(CycleEnergy(p, i, j));
  return r;
}

}  // namespace covplan
