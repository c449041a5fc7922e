// The fleet's parts alone: the assignment solver against brute force, and
// the equal-area and equal-cost regions on an open grid.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "planner/fleet/assignment.h"
#include "planner/fleet/division.h"

namespace covplan {
namespace {

double BruteForce(const std::vector<double>& c, int n) {
  std::vector<int> p(n);
  std::iota(p.begin(), p.end(), 0);
  double best = INFINITY;
  do {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += c[i * n + p[i]];
    best = std::min(best, s);
  } while (std::next_permutation(p.begin(), p.end()));
  return best;
}

TEST(Assignment, MatchesBruteForceOnRandomMatricesWithForbiddenPairs) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> cost(0.0, 100.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + trial % 7;
    std::vector<double> c(n * n);
    for (double& x : c) x = rng() % 5 == 0 ? INFINITY : cost(rng);
    const double want = BruteForce(c, n);
    const std::optional<double> got = MinAssignmentCost(c, n);
    if (!std::isfinite(want)) {
      EXPECT_FALSE(got.has_value()) << "trial " << trial;
    } else {
      ASSERT_TRUE(got.has_value()) << "trial " << trial;
      EXPECT_NEAR(*got, want, 1e-9) << "trial " << trial;
    }
  }
}

double BruteForceMatching(const std::vector<double>& c, int n, std::vector<int>& used) {
  int i = 0;
  while (i < n && used[i]) ++i;
  if (i == n) return 0.0;
  used[i] = 1;
  double best = INFINITY;
  for (int j = i + 1; j < n; ++j) {
    if (used[j] || !std::isfinite(c[i * n + j])) continue;
    used[j] = 1;
    best = std::min(best, c[i * n + j] + BruteForceMatching(c, n, used));
    used[j] = 0;
  }
  used[i] = 0;
  return best;
}

TEST(PerfectMatching, TheHalfAssignmentBoundsTheBruteForceMatchingFromBelow) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> cost(0.0, 50.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 2 + 2 * (trial % 5);
    std::vector<double> c(n * n, INFINITY);
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        if (rng() % 4 == 0) continue;
        c[i * n + j] = c[j * n + i] = std::round(cost(rng) * 1000.0) / 1000.0;
      }
    }
    std::vector<int> used(n, 0);
    const double want = BruteForceMatching(c, n, used);
    const std::optional<double> got = PerfectMatchingLowerBound(c, n);
    if (!got.has_value()) {
      EXPECT_FALSE(std::isfinite(want)) << "trial " << trial;  // no assignment: no matching
    } else {
      EXPECT_LE(*got, want + 1e-9) << "trial " << trial;
      if (n == 2 && std::isfinite(want)) {
        EXPECT_NEAR(*got, want, 1e-9);  // one edge: exact
      }
    }
  }
}

TEST(EqualArea, RegionsOfAnOpenGridAreEqualConnectedAndCoverEverything) {
  std::vector<uint8_t> free(30 * 40, 1);
  const Grid g(30, 40, 1.0, {0.0, 0.0}, free);
  for (int k : {2, 3, 5}) {
    std::vector<std::optional<Pose2>> starts;
    for (int r = 0; r < k; ++r) starts.push_back(Pose2{0.5 + 8.0 * r, 0.5 + 5.0 * r, 0.0});
    std::vector<std::vector<int64_t>> regions = EqualAreaRegions(g, g, starts);
    int64_t total = 0, lo = INT64_MAX, hi = 0;
    for (const auto& r : regions) {
      total += static_cast<int64_t>(r.size());
      lo = std::min<int64_t>(lo, r.size());
      hi = std::max<int64_t>(hi, r.size());
    }
    EXPECT_EQ(total, g.size()) << "k=" << k;
    EXPECT_LE(hi - lo, 2) << "k=" << k;
    std::vector<std::vector<int64_t>> copy = regions;
    EXPECT_EQ(MakeRegionsConnected(g, &copy), 0) << "k=" << k << ": a region was not connected";
  }
}

TEST(BalancedRegions, RegionsOfEqualCostAreConnectedAndCoverEverything) {
  // Cells of the left half cost three times those of the right half: a
  // robot starting on the left gets fewer cells than one on the right.
  std::vector<uint8_t> free(30 * 40, 1);
  const Grid g(30, 40, 1.0, {0.0, 0.0}, free);
  std::vector<double> cost(static_cast<size_t>(g.size()));
  for (int64_t i = 0; i < g.size(); ++i) cost[i] = g.FromIndex(i).col < 20 ? 3.0 : 1.0;
  double total_cost = 0.0;
  for (double c : cost) total_cost += c;  // 30 * (20 * 3 + 20) = 2400
  for (int k : {2, 3, 4}) {
    SCOPED_TRACE(k);
    std::vector<std::optional<Pose2>> starts;
    for (int r = 0; r < k; ++r) starts.push_back(Pose2{0.5 + 39.0 * r / (k - 1), 15.5, 0.0});
    std::vector<std::vector<int64_t>> regions = BalancedRegions(g, g, starts, cost);
    ASSERT_EQ(regions.size(), static_cast<size_t>(k));
    int64_t cells = 0;
    std::vector<double> load(k, 0.0);
    for (int r = 0; r < k; ++r) {
      cells += static_cast<int64_t>(regions[r].size());
      for (int64_t i : regions[r]) load[r] += cost[i];
    }
    EXPECT_EQ(cells, g.size());
    for (int r = 0; r < k; ++r) {
      // Within three of the costliest cells of an equal share.
      EXPECT_NEAR(load[r], total_cost / k, 9.0) << "robot " << r;
    }
    // The robot on the costly side sweeps fewer cells than the one on the cheap side.
    EXPECT_LT(regions[0].size(), regions[k - 1].size());
    std::vector<std::vector<int64_t>> copy = regions;
    EXPECT_EQ(MakeRegionsConnected(g, &copy), 0) << "a region was not connected";
  }
}

}  // namespace
}  // namespace covplan
