// Test helpers for the GTSP solver: seeded random instances and an exact
// Held-Karp dynamic program over the sets, the independent reference the
// solver is checked against.
//
//   GtspInstance inst = RandomInstance(/*seed=*/3, /*num_sets=*/7, /*max_set=*/3, kAsymmetric);
//   double opt = HeldKarpOptimum(inst);   // exponential: keep num_sets <= ~12
#ifndef COVPLAN_TESTS_GTSP_GTSP_TEST_UTIL_H_
#define COVPLAN_TESTS_GTSP_GTSP_TEST_UTIL_H_

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "planner/tour/gtsp/gtsp.h"

namespace covplan::testing_gtsp {

enum CostKind { kEuclidean, kAsymmetric };

// `num_sets` sets of 1..max_set_size vertices (vertex ids shuffled across
// sets). Euclidean: points in a 1000x1000 square. Asymmetric: Euclidean plus
// a random direction-dependent surcharge, so c(i,j) != c(j,i).
inline GtspInstance RandomInstance(unsigned seed, int num_sets, int max_set_size, CostKind kind,
                                   int min_set_size = 1) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> size_dist(min_set_size, max_set_size);
  std::vector<int> sizes(num_sets);
  int n = 0;
  for (int& s : sizes) n += (s = size_dist(rng));
  std::vector<int> ids(n);
  for (int i = 0; i < n; ++i) ids[i] = i;
  std::shuffle(ids.begin(), ids.end(), rng);
  GtspInstance inst;
  inst.num_vertices = n;
  inst.sets.resize(num_sets);
  for (int s = 0, k = 0; s < num_sets; ++s) {
    for (int j = 0; j < sizes[s]; ++j) inst.sets[s].push_back(ids[k++]);
  }
  std::uniform_real_distribution<double> coord(0.0, 1000.0), extra(0.0, 300.0);
  std::vector<double> x(n), y(n);
  for (int i = 0; i < n; ++i) {
    x[i] = coord(rng);
    y[i] = coord(rng);
  }
  inst.costs.assign(static_cast<size_t>(n) * n, 0.0);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      double d = std::round(std::hypot(x[i] - x[j], y[i] - y[j]));
      if (kind == kAsymmetric) d += std::round(extra(rng));
      inst.costs[static_cast<size_t>(i) * n + j] = d;
    }
  }
  return inst;
}

// Exact optimum by dynamic programming over subsets of sets (the tour is a
// cycle, so it starts w.l.o.g. in set 0).
inline double HeldKarpOptimum(const GtspInstance& inst) {
  const int m = static_cast<int>(inst.sets.size());
  const double inf = std::numeric_limits<double>::infinity();
  if (m == 1) {
    double best = inf;
    for (int v : inst.sets[0]) best = std::min(best, inst.cost(v, v));
    return best;
  }
  const int n = inst.num_vertices;
  const int full = 1 << (m - 1);  // bit s-1 <=> set s visited, s >= 1
  std::vector<int> set_of(n);
  for (int s = 0; s < m; ++s) {
    for (int v : inst.sets[s]) set_of[v] = s;
  }
  double best = inf;
  std::vector<double> dp(static_cast<size_t>(full) * n);
  for (int u : inst.sets[0]) {
    std::fill(dp.begin(), dp.end(), inf);
    for (int v = 0; v < n; ++v) {
      if (set_of[v] != 0) dp[static_cast<size_t>(1 << (set_of[v] - 1)) * n + v] = inst.cost(u, v);
    }
    for (int mask = 1; mask < full; ++mask) {
      for (int v = 0; v < n; ++v) {
        const double dv = dp[static_cast<size_t>(mask) * n + v];
        if (dv == inf) continue;
        for (int w = 0; w < n; ++w) {
          const int sw = set_of[w];
          if (sw == 0 || (mask & (1 << (sw - 1)))) continue;
          double& slot = dp[static_cast<size_t>(mask | (1 << (sw - 1))) * n + w];
          slot = std::min(slot, dv + inst.cost(v, w));
        }
      }
    }
    for (int v = 0; v < n; ++v) {
      const double dv = dp[static_cast<size_t>(full - 1) * n + v];
      if (dv != inf) best = std::min(best, dv + inst.cost(v, u));
    }
  }
  return best;
}

}  // namespace covplan::testing_gtsp

#endif  // COVPLAN_TESTS_GTSP_GTSP_TEST_UTIL_H_
