// Internal, search-friendly form of a GtspInstance and the tour type the
// search manipulates. Vertices are renumbered so that each set occupies a
// contiguous id range, and besides the row-major matrix every set keeps two
// compact blocks (arcs into the set, arcs out of the set), so "best vertex of
// set S between a and b" reads two short runs of a small, cache-resident block.
//
//   Problem p = Problem::Build(instance);       // once per solve
//   SearchTour t; t.Reset(p); t.Append(v); ...  // internal vertex ids
//
// Thread-safety: a built Problem is immutable and may be shared by threads;
// SearchTour is a plain value owned by one thread.
#ifndef COVPLAN_PLANNER_TOUR_GTSP_GTSP_PROBLEM_H_
#define COVPLAN_PLANNER_TOUR_GTSP_GTSP_PROBLEM_H_

#include <algorithm>
#include <cmath>
#include <vector>

#include "planner/tour/gtsp/gtsp.h"

namespace covplan::gtsp_internal {

struct Problem {
  int n = 0;                 // vertices
  int m = 0;                 // sets
  std::vector<double> cost;  // n*n, internal ids, cost[i*n+j] = arc i->j
  // Set blocks, both at offset n*set_begin[s]: to_set[.. + a*|s| + k] is the
  // arc a -> (k-th vertex of s), from_set[.. + b*|s| + k] the arc k-th -> b.
  std::vector<double> to_set_block;
  std::vector<double> from_set_block;
  std::vector<int> set_begin;    // m+1; set s = internal ids [set_begin[s], set_begin[s+1])
  std::vector<int> set_of;       // internal id -> set
  std::vector<int> to_external;  // internal id -> instance vertex id
  std::vector<int> to_internal;  // instance vertex id -> internal id
  // Per set, the other sets ordered by min_{a in S, b in T} min(c(a,b), c(b,a)),
  // truncated to kNearSets entries.
  static constexpr int kNearSets = 24;
  std::vector<std::vector<int>> near_sets;

  static Problem Build(const GtspInstance& instance);

  double c(int i, int j) const { return cost[static_cast<size_t>(i) * n + j]; }
  const double* row(int i) const { return &cost[static_cast<size_t>(i) * n]; }
  // The |s| arc costs a -> v for v in set s, in id order.
  const double* to_set(int s, int a) const {
    return &to_set_block[static_cast<size_t>(n) * set_begin[s] +
                         static_cast<size_t>(a) * set_size(s)];
  }
  // The |s| arc costs v -> b for v in set s, in id order.
  const double* from_set(int s, int b) const {
    return &from_set_block[static_cast<size_t>(n) * set_begin[s] +
                           static_cast<size_t>(b) * set_size(s)];
  }
  int set_size(int s) const { return set_begin[s + 1] - set_begin[s]; }
  // The cheapest way through set s from a to b: sets `v` to the vertex of s
  // (the first in id order on ties) and returns c(a, v) + c(v, b).
  double BestBetween(int a, int b, int s, int* v) const {
    const double* in = to_set(s, a);
    const double* out = from_set(s, b);
    const int size = set_size(s);
    double best = in[0] + out[0];
    int arg = 0;
    for (int k = 1; k < size; ++k) {
      const double d = in[k] + out[k];
      if (d < best) {
        best = d;
        arg = k;
      }
    }
    *v = set_begin[s] + arg;
    return best;
  }
};

// True if `cost` beats `than` by more than rounding (relative 1e-9): how
// trials and populations decide that a tour is a new best.
inline bool Cheaper(double cost, double than) {
  return cost < than - 1e-9 * std::max(1.0, std::abs(than));
}

// A (possibly partial) cyclic tour: at most one vertex per set, with O(1)
// position lookup by set.
struct SearchTour {
  std::vector<int> seq;  // internal vertex ids in visiting order
  std::vector<int> pos;  // per set: index in seq, or -1 if the set is absent
  double cost = 0.0;     // cycle cost of seq (closing arc included)

  void Reset(const Problem& p) {
    seq.clear();
    pos.assign(p.m, -1);
    cost = 0.0;
  }
  int size() const { return static_cast<int>(seq.size()); }
  int next(int i) const { return i + 1 == size() ? 0 : i + 1; }
  int prev(int i) const { return i == 0 ? size() - 1 : i - 1; }
  void RebuildPositions(const Problem& p, int from = 0) {
    for (int i = from; i < size(); ++i) pos[p.set_of[seq[i]]] = i;
  }
  void RecomputeCost(const Problem& p) {
    double total = 0.0;
    for (int i = 0; i < size(); ++i) total += p.c(seq[i], seq[next(i)]);
    cost = total;
  }
  // Inserts v right after index `after` (-1 or any index when empty); updates
  // positions and cost.
  void InsertAfter(const Problem& p, int after, int v);
  // Removes every vertex whose set is flagged in `drop` (indexed by set).
  void RemoveSets(const Problem& p, const std::vector<char>& drop);
};

// Exact re-selection of the vertex in every set for the fixed set order of
// `t` (shortest cycle through the layered graph). Returns true if improved.
// `scratch` buffers are reused across calls to avoid allocation.
struct ClusterOptScratch {
  std::vector<double> dist;
  std::vector<int> parent;
  std::vector<int> layer_offset;
  std::vector<int> best_seq;
};
bool ClusterOptimize(const Problem& p, SearchTour& t, ClusterOptScratch& scratch);

}  // namespace covplan::gtsp_internal

#endif  // COVPLAN_PLANNER_TOUR_GTSP_GTSP_PROBLEM_H_
