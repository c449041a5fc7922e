// The Held-Karp bound over cycles through a forced matching (one_tree.h):
// never above the cheapest such cycle found by enumeration, close to it on
// random Euclidean instances, and it prices the link between two far
// clusters that a matching relaxation leaves out.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "planner/fleet/assignment.h"
#include "planner/fleet/one_tree.h"

namespace covplan {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Instance {
  int n = 0;
  std::vector<double> costs;
  std::vector<int> partner;  // vertex 2i with 2i + 1
};

// Pairs of points: each pair's forced edge costs its length, free edges
// their Euclidean length.
Instance Euclidean(const std::vector<double>& x, const std::vector<double>& y) {
  Instance in;
  in.n = static_cast<int>(x.size());
  in.costs.resize(static_cast<size_t>(in.n) * in.n);
  in.partner.resize(in.n);
  for (int i = 0; i < in.n; ++i) {
    in.partner[i] = i ^ 1;
    for (int j = 0; j < in.n; ++j) {
      in.costs[static_cast<size_t>(i) * in.n + j] =
          i == j ? kInf : std::hypot(x[i] - x[j], y[i] - y[j]);
    }
  }
  return in;
}

// The cheapest cycle through every forced pair, by enumeration: pair 0
// first as (0, 1), then every order and direction of the others.
double CheapestCycle(const Instance& in) {
  const int m = in.n / 2;
  std::vector<int> order(m - 1);
  std::iota(order.begin(), order.end(), 1);
  auto c = [&](int a, int b) { return in.costs[static_cast<size_t>(a) * in.n + b]; };
  double best = kInf;
  do {
    for (int flips = 0; flips < (1 << (m - 1)); ++flips) {
      double total = c(0, 1);
      int at = 1;
      for (int i = 0; i < m - 1; ++i) {
        const int first = 2 * order[i] + ((flips >> i) & 1);
        total += c(at, first) + c(first, first ^ 1);
        at = first ^ 1;
      }
      best = std::min(best, total + c(at, 0));
    }
  } while (std::next_permutation(order.begin(), order.end()));
  return best;
}

TEST(HeldKarpBound, NeverAboveTheCheapestCycleAndCloseToIt) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(0.0, 10.0);
  double ratio_sum = 0.0;
  const int trials = 40;
  for (int trial = 0; trial < trials; ++trial) {
    const int n = 2 * (2 + trial % 6);  // 4 .. 14 vertices
    std::vector<double> x(n), y(n);
    for (int i = 0; i < n; ++i) x[i] = coord(rng), y[i] = coord(rng);
    const Instance in = Euclidean(x, y);
    const double exact = CheapestCycle(in);
    const std::optional<double> lb = HeldKarpBound(in.costs, in.partner, 50'000'000);
    ASSERT_TRUE(lb.has_value()) << "trial " << trial;
    EXPECT_LE(*lb, exact + 1e-6) << "trial " << trial;
    ratio_sum += *lb / exact;
  }
  // Held-Karp is within a few per cent on random Euclidean instances.
  EXPECT_GT(ratio_sum / trials, 0.95);
}

TEST(HeldKarpBound, PricesTheLinkBetweenFarClusters) {
  // Two clusters of three short pairs, 100 apart: any cycle crosses twice.
  std::vector<double> x, y;
  for (int cluster = 0; cluster < 2; ++cluster) {
    for (int p = 0; p < 3; ++p) {
      x.push_back(100.0 * cluster + p), y.push_back(0.0);
      x.push_back(100.0 * cluster + p), y.push_back(1.0);
    }
  }
  const Instance in = Euclidean(x, y);
  const double exact = CheapestCycle(in);
  const std::optional<double> lb = HeldKarpBound(in.costs, in.partner, 50'000'000);
  ASSERT_TRUE(lb.has_value());
  EXPECT_LE(*lb, exact + 1e-6);
  EXPECT_GE(*lb, 196.0);  // the two crossings, at least 97 each
  // The matching over the free edges stays inside the clusters.
  std::vector<double> free = in.costs;
  for (int i = 0; i < in.n; ++i) free[static_cast<size_t>(i) * in.n + (i ^ 1)] = kInf;
  const std::optional<double> matched = PerfectMatchingLowerBound(free, in.n);
  ASSERT_TRUE(matched.has_value());
  EXPECT_LT(*matched + 6.0, 50.0);
}

TEST(HeldKarpBound, NoCycleWhenAVertexHasNoFreeEdge) {
  std::vector<double> x = {0, 0, 5, 5, 9, 9}, y = {0, 1, 0, 1, 0, 1};
  Instance in = Euclidean(x, y);
  // Vertex 2 (not the 1-tree's special vertex 0) reaches only its mate.
  for (int j = 0; j < in.n; ++j) {
    if (j != 3) {
      in.costs[static_cast<size_t>(2) * in.n + j] = kInf;
      in.costs[static_cast<size_t>(j) * in.n + 2] = kInf;
    }
  }
  EXPECT_FALSE(HeldKarpBound(in.costs, in.partner, 1'000'000).has_value());
}

}  // namespace
}  // namespace covplan
