#include "planner/tour/gtsp/gtsp_problem.h"

#include <algorithm>
#include <limits>
#include <numeric>

namespace covplan::gtsp_internal {

Problem Problem::Build(const GtspInstance& instance) {
  Problem p;
  p.n = instance.num_vertices;
  p.m = static_cast<int>(instance.sets.size());
  p.set_begin.assign(p.m + 1, 0);
  p.set_of.resize(p.n);
  p.to_external.reserve(p.n);
  p.to_internal.assign(p.n, -1);
  for (int s = 0; s < p.m; ++s) {
    p.set_begin[s] = static_cast<int>(p.to_external.size());
    for (int v : instance.sets[s]) {
      p.to_internal[v] = static_cast<int>(p.to_external.size());
      p.set_of[p.to_external.size()] = s;
      p.to_external.push_back(v);
    }
  }
  p.set_begin[p.m] = p.n;

  const size_t nn = static_cast<size_t>(p.n) * p.n;
  p.cost.resize(nn);
  for (int i = 0; i < p.n; ++i) {
    const double* src = &instance.costs[static_cast<size_t>(p.to_external[i]) * p.n];
    double* dst = &p.cost[static_cast<size_t>(i) * p.n];
    for (int j = 0; j < p.n; ++j) dst[j] = src[p.to_external[j]];
  }
  p.to_set_block.resize(nn);
  p.from_set_block.resize(nn);
  for (int s = 0; s < p.m; ++s) {
    const int lo = p.set_begin[s], size = p.set_size(s);
    for (int a = 0; a < p.n; ++a) {
      double* to = &p.to_set_block[static_cast<size_t>(p.n) * lo + static_cast<size_t>(a) * size];
      double* from =
          &p.from_set_block[static_cast<size_t>(p.n) * lo + static_cast<size_t>(a) * size];
      for (int k = 0; k < size; ++k) {
        to[k] = p.c(a, lo + k);
        from[k] = p.c(lo + k, a);
      }
    }
  }

  // Set-to-set proximity, used by the distance removal and the local moves.
  std::vector<double> set_dist(static_cast<size_t>(p.m) * p.m,
                               std::numeric_limits<double>::infinity());
  for (int i = 0; i < p.n; ++i) {
    const int si = p.set_of[i];
    const double* crow = p.row(i);
    for (int j = 0; j < p.n; ++j) {
      const int sj = p.set_of[j];
      const double d = crow[j];
      double& ab = set_dist[static_cast<size_t>(si) * p.m + sj];
      double& ba = set_dist[static_cast<size_t>(sj) * p.m + si];
      if (d < ab) ab = d;
      if (d < ba) ba = d;
    }
  }
  p.near_sets.assign(p.m, {});
  std::vector<int> order;
  for (int s = 0; s < p.m; ++s) {
    order.clear();
    for (int t = 0; t < p.m; ++t) {
      if (t != s) order.push_back(t);
    }
    const int keep = std::min<int>(kNearSets, static_cast<int>(order.size()));
    const double* drow = &set_dist[static_cast<size_t>(s) * p.m];
    std::partial_sort(order.begin(), order.begin() + keep, order.end(),
                      [&](int a, int b) { return drow[a] != drow[b] ? drow[a] < drow[b] : a < b; });
    p.near_sets[s].assign(order.begin(), order.begin() + keep);
  }
  return p;
}

void SearchTour::InsertAfter(const Problem& p, int after, int v) {
  if (seq.empty()) {
    seq.push_back(v);
    pos[p.set_of[v]] = 0;
    cost = p.c(v, v);
    return;
  }
  const int a = seq[after];
  const int b = seq[next(after)];
  cost += p.c(a, v) + p.c(v, b) - p.c(a, b);
  seq.insert(seq.begin() + after + 1, v);
  RebuildPositions(p, after + 1);
}

void SearchTour::RemoveSets(const Problem& p, const std::vector<char>& drop) {
  int w = 0;
  for (int i = 0; i < size(); ++i) {
    const int v = seq[i];
    const int s = p.set_of[v];
    if (drop[s]) {
      pos[s] = -1;
    } else {
      pos[s] = w;
      seq[w++] = v;
    }
  }
  seq.resize(w);
  RecomputeCost(p);
}

bool ClusterOptimize(const Problem& p, SearchTour& t, ClusterOptScratch& sc) {
  const int len = t.size();
  if (len == 0) return false;
  if (len == 1) {
    const int s = p.set_of[t.seq[0]];
    int best = t.seq[0];
    for (int v = p.set_begin[s]; v < p.set_begin[s + 1]; ++v) {
      if (p.c(v, v) < p.c(best, best)) best = v;
    }
    if (p.c(best, best) < t.cost - 1e-9) {
      t.seq[0] = best;
      t.cost = p.c(best, best);
      return true;
    }
    return false;
  }
  // Start the layered graph at the smallest set: fewest shortest-path runs.
  int start = 0;
  for (int i = 1; i < len; ++i) {
    if (p.set_size(p.set_of[t.seq[i]]) < p.set_size(p.set_of[t.seq[start]])) start = i;
  }
  auto set_at = [&](int layer) { return p.set_of[t.seq[(start + layer) % len]]; };
  sc.layer_offset.resize(len + 1);
  sc.layer_offset[0] = 0;
  for (int l = 0; l < len; ++l) sc.layer_offset[l + 1] = sc.layer_offset[l] + p.set_size(set_at(l));
  sc.dist.resize(sc.layer_offset[len]);
  sc.parent.resize(sc.layer_offset[len]);
  sc.best_seq.resize(len);

  double best_cost = t.cost - 1e-9;
  bool improved = false;
  const int s0 = set_at(0);
  for (int u = p.set_begin[s0]; u < p.set_begin[s0 + 1]; ++u) {
    // Layer 1 from u.
    {
      const int s1 = set_at(1 % len);
      const double* to = p.to_set(s1, u);
      for (int k = 0; k < p.set_size(s1); ++k) {
        sc.dist[sc.layer_offset[1] + k] = to[k];
        sc.parent[sc.layer_offset[1] + k] = u;
      }
    }
    for (int l = 2; l < len; ++l) {
      const int sp = set_at(l - 1), sl = set_at(l);
      const int op = sc.layer_offset[l - 1], ol = sc.layer_offset[l];
      for (int k = 0, v = p.set_begin[sl]; v < p.set_begin[sl + 1]; ++v, ++k) {
        const double* into_v = p.from_set(sp, v);
        double best = std::numeric_limits<double>::infinity();
        int arg = -1;
        for (int j = 0, w = p.set_begin[sp]; w < p.set_begin[sp + 1]; ++w, ++j) {
          const double d = sc.dist[op + j] + into_v[j];
          if (d < best) {
            best = d;
            arg = w;
          }
        }
        sc.dist[ol + k] = best;
        sc.parent[ol + k] = arg;
      }
    }
    const int sl = set_at(len - 1), ol = sc.layer_offset[len - 1];
    const double* into_u = p.from_set(sl, u);
    double close = std::numeric_limits<double>::infinity();
    int last = -1;
    for (int k = 0, w = p.set_begin[sl]; w < p.set_begin[sl + 1]; ++w, ++k) {
      const double d = sc.dist[ol + k] + into_u[k];
      if (d < close) {
        close = d;
        last = w;
      }
    }
    if (close < best_cost) {
      best_cost = close;
      improved = true;
      int v = last;
      for (int l = len - 1; l >= 1; --l) {
        sc.best_seq[l] = v;
        const int sv = p.set_of[v];
        v = sc.parent[sc.layer_offset[l] + (v - p.set_begin[sv])];
      }
      sc.best_seq[0] = u;
    }
  }
  if (!improved) return false;
  for (int l = 0; l < len; ++l) t.seq[(start + l) % len] = sc.best_seq[l];
  t.RecomputeCost(p);
  return true;
}

}  // namespace covplan::gtsp_internal
