// The split of an ordered tour into charge cycles is optimal: compared with
// brute force over every set of break points on small random tours.
#include <limits>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "planner/energy/charge_split.h"

namespace covplan {
namespace {

// Least total over all break subsets (2^(n-1)), +inf when none fits.
double BruteForce(const SplitProblem& p, double budget, int* cycles) {
  const int n = p.size();
  double best = std::numeric_limits<double>::infinity();
  for (uint32_t mask = 0; mask < (1u << (n - 1)); ++mask) {
    double total = 0.0;
    int first = 0, count = 0;
    bool ok = true;
    for (int k = 0; k < n && ok; ++k) {
      const bool cut = k + 1 == n || (mask >> k & 1u);
      if (!cut) continue;
      if (k + 1 < n && !p.BreakAfter(k)) ok = false;
      double e = p.out[first] + p.back[k];
      for (int t = first; t <= k; ++t) e += p.work[t] + (t < k ? p.link[t] : 0.0);
      if (e > budget) ok = false;
      total += e;
      ++count;
      first = k + 1;
    }
    if (ok && total < best) best = total, *cycles = count;
  }
  return best;
}

TEST(SplitTour, MatchesBruteForceOnRandomTours) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> leg(0.5, 6.0), work(0.1, 5.0), link(0.0, 4.0);
  int feasible = 0, multi = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 11;
    SplitProblem p;
    for (int k = 0; k < n; ++k) {
      p.out.push_back(leg(rng));
      p.back.push_back(leg(rng));
      p.work.push_back(work(rng));
      if (k + 1 < n) p.link.push_back(link(rng));
      p.break_after.push_back(rng() % 4 != 0);
    }
    const double budget = 8.0 + (trial % 7) * 3.0;
    int cycles = 0;
    const double want = BruteForce(p, budget, &cycles);
    absl::StatusOr<SplitResult> got = SplitTour(p, budget);
    SCOPED_TRACE(trial);
    if (want == std::numeric_limits<double>::infinity()) {
      EXPECT_EQ(got.status().code(), absl::StatusCode::kFailedPrecondition);
      continue;
    }
    ASSERT_TRUE(got.ok()) << got.status();
    ++feasible;
    multi += got->cycles.size() > 1;
    EXPECT_NEAR(got->total, want, 1e-9);
    // The cycles tile the tour in order, each fits, breaks where allowed.
    int next = 0;
    double sum = 0.0;
    for (size_t c = 0; c < got->cycles.size(); ++c) {
      EXPECT_EQ(got->cycles[c].first, next);
      EXPECT_LE(got->energy[c], budget);
      EXPECT_DOUBLE_EQ(got->energy[c], CycleEnergy(p, got->cycles[c].first, got->cycles[c].second));
      EXPECT_TRUE(p.BreakAfter(got->cycles[c].second));
      next = got->cycles[c].second + 1;
      sum += got->energy[c];
    }
    EXPECT_EQ(next, n);
    EXPECT_NEAR(sum, got->total, 1e-9);
  }
  // The random tours exercise both outcomes and real splitting.
  EXPECT_GT(feasible, 100);
  EXPECT_GT(multi, 50);
}

TEST(SplitTour, RefusesMalformedInput) {
  SplitProblem p;
  p.out = {1, 1};
  p.back = {1, 1};
  p.work = {1, 1};
  p.link = {};
  EXPECT_EQ(SplitTour(p, 10).status().code(), absl::StatusCode::kInvalidArgument);
  p.link = {-1};
  EXPECT_EQ(SplitTour(p, 10).status().code(), absl::StatusCode::kInvalidArgument);
  p.link = {1};
  absl::StatusOr<SplitResult> r = SplitTour(p, 10);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->cycles.size(), 1u);
  EXPECT_DOUBLE_EQ(r->total, 5.0);
  r = SplitTour(p, 4);  // 1 + 1 + 1 each: two cycles
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->cycles.size(), 2u);
  EXPECT_DOUBLE_EQ(r->total, 6.0);
}

}  // namespace
}  // namespace covplan
