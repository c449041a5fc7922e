#include "planner/fleet/one_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace covplan {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct OneTree {
  bool connected = false;
  double value = 0.0;       // under the penalised costs, less 2 sum p
  std::vector<int> degree;  // per vertex, forced edges included
};

class Penalised {
 public:
  Penalised(const std::vector<double>& costs, const std::vector<int>& partner)
      : c_(costs), partner_(partner), n_(static_cast<int>(partner.size())), p_(n_, 0.0) {}

  int n() const { return n_; }
  std::vector<double>& penalties() { return p_; }
  double cost(int i, int j) const { return c_[static_cast<size_t>(i) * n_ + j] + p_[i] + p_[j]; }

  // The least 1-tree at vertex 0: a spanning tree of vertices 1..n-1 that
  // holds every forced edge among them (Prim, a forced partner's key set
  // to -inf as soon as its mate joins), plus vertex 0's forced edge and its
  // cheapest free edge.
  OneTree Solve() const {
    OneTree t;
    t.degree.assign(n_, 0);
    std::vector<double> key(n_, kInf);
    std::vector<int> parent(n_, -1);
    std::vector<char> in(n_, 0);
    in[0] = 1;
    key[1] = 0.0;
    double sum = 0.0;
    for (int step = 1; step < n_; ++step) {
      int u = -1;
      for (int v = 1; v < n_; ++v) {
        if (!in[v] && (u < 0 || key[v] < key[u])) u = v;
      }
      if (key[u] == kInf) return t;  // the free edges leave the graph disconnected
      in[u] = 1;
      if (parent[u] >= 0) {
        sum += cost(u, parent[u]);
        ++t.degree[u];
        ++t.degree[parent[u]];
      }
      for (int v = 1; v < n_; ++v) {
        if (in[v]) continue;
        const double w = v == partner_[u] ? -kInf : cost(u, v);
        if (w < key[v]) key[v] = w, parent[v] = u;
      }
    }
    const int mate = partner_[0];
    int best = -1;
    for (int v = 1; v < n_; ++v) {
      if (v != mate && (best < 0 || cost(0, v) < cost(0, best))) best = v;
    }
    if (best < 0 || cost(0, best) == kInf) return t;
    sum += cost(0, mate) + cost(0, best);
    t.degree[0] = 2;
    ++t.degree[mate];
    ++t.degree[best];
    for (double p : p_) sum -= 2.0 * p;
    t.value = sum;
    t.connected = true;
    return t;
  }

  // A cycle through the forced edges, nearest free neighbour first (an
  // upper bound that aims the subgradient steps); +inf when it cannot close.
  double NearestNeighbourCycle() const {
    std::vector<char> seen(n_, 0);
    int at = 0;
    double total = 0.0;
    for (int left = n_; left > 0; left -= 2) {
      seen[at] = seen[partner_[at]] = 1;
      total += c_[static_cast<size_t>(at) * n_ + partner_[at]];
      at = partner_[at];
      if (left == 2) break;
      int next = -1;
      for (int v = 0; v < n_; ++v) {
        if (!seen[v] && (next < 0 || Raw(at, v) < Raw(at, next))) next = v;
      }
      if (Raw(at, next) == kInf) return kInf;
      total += Raw(at, next);
      at = next;
    }
    return total + Raw(at, 0);
  }

 private:
  double Raw(int i, int j) const { return c_[static_cast<size_t>(i) * n_ + j]; }

  const std::vector<double>& c_;
  const std::vector<int>& partner_;
  int n_;
  std::vector<double> p_;
};

}  // namespace

std::optional<double> HeldKarpBound(const std::vector<double>& costs,
                                    const std::vector<int>& partner, int64_t work_budget) {
  const int n = static_cast<int>(partner.size());
  if (n < 4 || costs.size() != static_cast<size_t>(n) * n) return std::nullopt;
  for (int v = 0; v < n; ++v) {
    bool free_edge = false;
    for (int w = 0; w < n && !free_edge; ++w)
      free_edge = w != v && w != partner[v] && costs[static_cast<size_t>(v) * n + w] < kInf;
    if (!free_edge) return std::nullopt;
  }
  Penalised graph(costs, partner);
  const double upper = graph.NearestNeighbourCycle();
  double best = -kInf;
  double lambda = 2.0;
  int stall = 0;
  const int64_t per_step = static_cast<int64_t>(n) * n;
  std::vector<double>& p = graph.penalties();
  for (int64_t work = 0; work + per_step <= work_budget || work == 0; work += per_step) {
    const OneTree t = graph.Solve();
    // Connectivity does not depend on the penalties: only the first step
    // can find the graph disconnected (a later one would be a numerical
    // failure, and the best bound so far stands).
    if (!t.connected) return best == -kInf ? std::nullopt : std::optional<double>(best);
    if (best == -kInf || t.value > best + 1e-9 * std::abs(best)) {
      best = t.value;
      stall = 0;
    } else if (++stall >= 10) {
      lambda /= 2.0;
      stall = 0;
      if (lambda < 1e-3) break;
    }
    double norm2 = 0.0;
    for (int v = 0; v < n; ++v) norm2 += (t.degree[v] - 2.0) * (t.degree[v] - 2.0);
    if (norm2 == 0.0) break;  // the 1-tree is a cycle: the bound is exact
    // Polyak's step towards a target above the best bound so far (the
    // nearest-neighbour cycle, or 5 % above the bound when it found none).
    const double floor = best + 1e-3 * std::abs(best) + 1e-9;
    const double target =
        std::isfinite(upper) ? std::max(upper, floor) : best + 0.05 * std::abs(best) + 1e-6;
    const double step = lambda * (target - t.value) / norm2;
    for (int v = 0; v < n; ++v) p[v] += step * (t.degree[v] - 2.0);
  }
  return best;
}

}  // namespace covplan
