#include "planner/fleet/assignment.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace covplan {

std::optional<double> MinAssignmentCost(const std::vector<double>& costs, int n) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // 1-based: column 0 is the virtual start of each augmenting path.
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0);
  std::vector<int> match(n + 1, 0), way(n + 1, 0);  // match[col] = row
  std::vector<double> dist(n + 1);
  std::vector<char> used(n + 1);
  for (int row = 1; row <= n; ++row) {
    match[0] = row;
    int col0 = 0;
    std::fill(dist.begin(), dist.end(), kInf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[col0] = 1;
      const int r = match[col0];
      double delta = kInf;
      int col1 = -1;
      const double* c = &costs[static_cast<size_t>(r - 1) * n];
      for (int col = 1; col <= n; ++col) {
        if (used[col]) continue;
        const double reduced = c[col - 1] - u[r] - v[col];
        if (reduced < dist[col]) dist[col] = reduced, way[col] = col0;
        if (dist[col] < delta) delta = dist[col], col1 = col;
      }
      if (col1 < 0 || !std::isfinite(delta)) return std::nullopt;
      for (int col = 0; col <= n; ++col) {
        if (used[col]) {
          u[match[col]] += delta;
          v[col] -= delta;
        } else {
          dist[col] -= delta;
        }
      }
      col0 = col1;
    } while (match[col0] != 0);
    do {  // flip the augmenting path
      const int col1 = way[col0];
      match[col0] = match[col1];
      col0 = col1;
    } while (col0 != 0);
  }
  double total = 0.0;
  for (int col = 1; col <= n; ++col)
    total += costs[static_cast<size_t>(match[col] - 1) * n + col - 1];
  return total;
}

std::optional<double> PerfectMatchingLowerBound(const std::vector<double>& costs, int n) {
  std::vector<double> c = costs;
  for (int i = 0; i < n; ++i) c[static_cast<size_t>(i) * n + i] = INFINITY;
  const std::optional<double> assigned = MinAssignmentCost(c, n);
  if (!assigned) return std::nullopt;
  return *assigned / 2.0;
}

}  // namespace covplan
