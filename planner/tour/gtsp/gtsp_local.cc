#include "planner/tour/gtsp/gtsp_local.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace covplan::gtsp_internal {
namespace {

double Eps(double cost) { return 1e-9 + 1e-12 * std::abs(cost); }

}  // namespace

LocalSearch::LocalSearch(const Problem& p) : p_(p) { active_.assign(p.m, 0); }

void LocalSearch::Activate(int set) {
  if (!active_[set]) {
    active_[set] = 1;
    queue_.push_back(set);
  }
}

void LocalSearch::ActivateAround(const SearchTour& t, int index) {
  Activate(p_.set_of[t.seq[t.prev(index)]]);
  Activate(p_.set_of[t.seq[index]]);
  Activate(p_.set_of[t.seq[t.next(index)]]);
}

void LocalSearch::RebuildPrefix(const SearchTour& t) {
  const int len = t.size();
  fwd_.resize(len);
  bwd_.resize(len);
  fwd_[0] = bwd_[0] = 0.0;
  for (int k = 1; k < len; ++k) {
    fwd_[k] = fwd_[k - 1] + p_.c(t.seq[k - 1], t.seq[k]);
    bwd_[k] = bwd_[k - 1] + p_.c(t.seq[k], t.seq[k - 1]);
  }
  prefix_valid_ = true;
}

bool LocalSearch::TryRelocate(SearchTour& t, int s) {
  const int i = t.pos[s];
  const int v = t.seq[i];
  const int a = t.seq[t.prev(i)], b = t.seq[t.next(i)];
  const double saving = p_.c(a, v) + p_.c(v, b) - p_.c(a, b);
  double best = saving - Eps(t.cost);
  int best_v = -1, best_after = -1;
  auto consider = [&](int x, int y) {
    int w;
    const double d = p_.BestBetween(x, y, s, &w) - p_.c(x, y);
    if (d < best) {
      best = d;
      best_v = w;
      best_after = x;
    }
  };
  consider(a, b);
  const std::vector<int>& near = p_.near_sets[s];
  const int limit = std::min<int>(kNeighbors, static_cast<int>(near.size()));
  for (int q = 0; q < limit; ++q) {
    const int j = t.pos[near[q]];
    if (j < 0 || j == i) continue;
    const int pj = t.prev(j), nj = t.next(j);
    if (pj != i) consider(t.seq[pj], t.seq[j]);
    if (nj != i) consider(t.seq[j], t.seq[nj]);
  }
  if (best_v < 0) return false;
  t.seq.erase(t.seq.begin() + i);
  t.pos[s] = -1;
  t.RebuildPositions(p_, i);
  t.cost -= saving;
  const int ia = t.pos[p_.set_of[a]];
  ActivateAround(t, ia);  // a and b are now adjacent
  t.InsertAfter(p_, t.pos[p_.set_of[best_after]], best_v);
  ActivateAround(t, t.pos[s]);
  prefix_valid_ = false;
  return true;
}

bool LocalSearch::TryTwoOpt(SearchTour& t, int s) {
  const int len = t.size();
  if (len < 4) return false;
  if (!prefix_valid_) RebuildPrefix(t);
  const int i = t.pos[s];
  const std::vector<int>& near = p_.near_sets[s];
  const int limit = std::min<int>(kNeighbors, static_cast<int>(near.size()));
  const double eps = Eps(t.cost);
  for (int q = 0; q < limit; ++q) {
    const int j = t.pos[near[q]];
    if (j < 0) continue;
    // Reversing seq[lo+1 .. hi] turns arcs (lo,lo+1), (hi,hi+1) into
    // (lo,hi), (lo+1,hi+1). Both choices below make s and near[q] adjacent:
    // through the first new arc (lo,hi = their positions) or through the
    // second (both ends shifted back by one).
    for (int variant = 0; variant < 2; ++variant) {
      int lo = std::min(i, j), hi = std::max(i, j);
      if (variant == 1) {
        lo = lo - 1;
        hi = hi - 1;
        if (lo < 0) continue;
      }
      if (hi - lo < 2 || (lo == 0 && hi == len - 1)) continue;
      const int a = t.seq[lo], b = t.seq[lo + 1], c = t.seq[hi], d = t.seq[(hi + 1) % len];
      const double inner = (bwd_[hi] - bwd_[lo + 1]) - (fwd_[hi] - fwd_[lo + 1]);
      const double delta = p_.c(a, c) + p_.c(b, d) - p_.c(a, b) - p_.c(c, d) + inner;
      if (delta < -eps) {
        std::reverse(t.seq.begin() + lo + 1, t.seq.begin() + hi + 1);
        t.RebuildPositions(p_, lo + 1);
        t.cost += delta;
        ActivateAround(t, lo);
        ActivateAround(t, lo + 1);
        ActivateAround(t, hi);
        ActivateAround(t, (hi + 1) % len);
        prefix_valid_ = false;
        return true;
      }
    }
  }
  return false;
}

bool LocalSearch::Run(SearchTour& t, const std::vector<int>* dirty, const StopToken& stop) {
  const double start_cost = t.cost;
  queue_.clear();
  std::fill(active_.begin(), active_.end(), 0);
  if (dirty == nullptr) {
    for (int v : t.seq) Activate(p_.set_of[v]);
  } else {
    for (int s : *dirty) {
      if (t.pos[s] >= 0) ActivateAround(t, t.pos[s]);
    }
  }
  prefix_valid_ = false;
  for (int round = 0; round < 100; ++round) {
    if (t.size() >= 3) {
      int steps = 0;
      for (size_t head = 0; head < queue_.size(); ++head) {
        const int s = queue_[head];
        active_[s] = 0;
        if (!TryRelocate(t, s)) TryTwoOpt(t, s);
        if ((++steps & 255) == 0 && stop.ShouldStop()) break;
      }
    }
    queue_.clear();
    std::fill(active_.begin(), active_.end(), 0);
    before_.assign(t.seq.begin(), t.seq.end());
    if (!ClusterOptimize(p_, t, cluster_scratch_) || stop.ShouldStop()) break;
    for (int i = 0; i < t.size(); ++i) {
      if (t.seq[i] != before_[i]) ActivateAround(t, i);
    }
    prefix_valid_ = false;
  }
  t.RecomputeCost(p_);
  return t.cost < start_cost - Eps(start_cost);
}

}  // namespace covplan::gtsp_internal
