#include "planner/tour/gtsp/gtsp_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace covplan::gtsp_internal {
namespace {

constexpr double kNoiseLevels[3] = {0.0, 0.1, 0.35};  // x mean tour arc
constexpr double kRemovalPower = 3.0;                 // rank bias of worst / distance removal
constexpr int kDistanceCandidates = 6;
constexpr int kWeightPeriod = 100;
constexpr double kWeightReaction = 0.25;
constexpr double kScoreBest = 3.0, kScoreBetter = 1.0, kScoreAccepted = 0.3;

double Eps(double cost) { return 1e-9 + 1e-12 * std::abs(cost); }

}  // namespace

LnsTrial::LnsTrial(const Problem& p, const SearchParams& params, uint64_t seed)
    : p_(p), params_(params), rng_(seed), local_(p) {
  drop_.assign(p.m, 0);
  for (int i = 0; i < kNumRemovals; ++i) {
    removal_weight_[i] = 1.0;
    removal_score_[i] = 0.0;
    removal_uses_[i] = 0;
  }
  for (int i = 0; i < kNumInsertions; ++i) {
    insertion_weight_[i] = 1.0;
    insertion_score_[i] = 0.0;
    insertion_uses_[i] = 0;
  }
}

int LnsTrial::Roulette(const double* weights, int count) {
  double total = 0.0;
  for (int i = 0; i < count; ++i) total += weights[i];
  double r = rng_.Uniform() * total;
  for (int i = 0; i < count; ++i) {
    r -= weights[i];
    if (r < 0.0) return i;
  }
  return count - 1;
}

void LnsTrial::EvaluateEdge(int a, int b, int set, double noise, Insertion& io) {
  int arg = -1;
  const double best = p_.BestBetween(a, b, set, &arg);
  double delta = best - p_.c(a, b);
  if (noise > 0.0) delta += noise * rng_.Uniform();
  if (delta < io.cost) {
    io.cost = delta;
    io.v = arg;
    io.after = a;
  }
}

void LnsTrial::Evaluate(const SearchTour& t, int set, double noise, Insertion& out) {
  out.cost = std::numeric_limits<double>::infinity();
  out.v = -1;
  out.after = -1;
  if (t.size() == 0) {
    for (int v = p_.set_begin[set]; v < p_.set_begin[set + 1]; ++v) {
      if (p_.c(v, v) < out.cost) {
        out.cost = p_.c(v, v);
        out.v = v;
      }
    }
    return;
  }
  if (params_.insertion_neighbors > 0) {
    // Arcs next to the nearest sets: on geometric instances the best position
    // is almost always among them, at a fraction of the memory traffic.
    int found = 0;
    const std::vector<int>& near = p_.near_sets[set];
    const int limit = std::min<int>(params_.insertion_neighbors, static_cast<int>(near.size()));
    for (int q = 0; q < limit; ++q) {
      const int j = t.pos[near[q]];
      if (j < 0) continue;
      ++found;
      const int v = t.seq[j];
      EvaluateEdge(t.seq[t.prev(j)], v, set, noise, out);
      EvaluateEdge(v, t.seq[t.next(j)], set, noise, out);
    }
    if (found >= 2 || found == t.size()) return;
  }
  // Memory-bound: every edge reads two rows of the set's cost blocks that are
  // rarely cached, so fetch a few edges ahead.
  constexpr int kAhead = 6;
  const int len = t.size();
  const int size = p_.set_size(set);
  const double* to_base = p_.to_set(set, 0);
  const double* from_base = p_.from_set(set, 0);
  for (int i = 0; i < len; ++i) {
    if (i + kAhead < len) {
      const int a = t.seq[i + kAhead];
      __builtin_prefetch(to_base + static_cast<size_t>(a) * size);
      __builtin_prefetch(from_base + static_cast<size_t>(a) * size);
    }
    EvaluateEdge(t.seq[i], t.seq[t.next(i)], set, noise, out);
  }
}

void LnsTrial::InsertSets(SearchTour& t, int mode, double noise) {
  const double noise_amp = noise > 0.0 && t.size() > 0 ? noise * t.cost / t.size() : 0.0;
  if (mode == kRandomOrder) {
    for (int i = static_cast<int>(removed_.size()) - 1; i > 0; --i) {
      std::swap(removed_[i], removed_[rng_.UniformInt(i + 1)]);
    }
    Insertion ins;
    for (int s : removed_) {
      Evaluate(t, s, noise_amp, ins);
      t.InsertAfter(p_, ins.after < 0 ? 0 : t.pos[p_.set_of[ins.after]], ins.v);
    }
    removed_.clear();
    return;
  }
  cache_.resize(removed_.size());
  for (size_t j = 0; j < removed_.size(); ++j) Evaluate(t, removed_[j], noise_amp, cache_[j]);
  while (!removed_.empty()) {
    size_t pick = 0;
    for (size_t j = 1; j < removed_.size(); ++j) {
      const bool better = mode == kNearest ? cache_[j].cost < cache_[pick].cost
                                           : cache_[j].cost > cache_[pick].cost;
      if (better) pick = j;
    }
    const Insertion ins = cache_[pick];
    removed_[pick] = removed_.back();
    removed_.pop_back();
    cache_[pick] = cache_.back();
    cache_.pop_back();
    const int at = ins.after < 0 ? 0 : t.pos[p_.set_of[ins.after]];
    t.InsertAfter(p_, at, ins.v);
    // Only the arc (after, old successor) disappeared; the two new arcs are
    // the only new positions to check.
    const int i = t.pos[p_.set_of[ins.v]];
    const int a = t.seq[t.prev(i)], b = t.seq[t.next(i)];
    for (size_t j = 0; j < removed_.size(); ++j) {
      if (cache_[j].after == ins.after) {
        Evaluate(t, removed_[j], noise_amp, cache_[j]);
      } else {
        EvaluateEdge(a, ins.v, removed_[j], noise_amp, cache_[j]);
        EvaluateEdge(ins.v, b, removed_[j], noise_amp, cache_[j]);
      }
    }
  }
}

void LnsTrial::Remove(SearchTour& t, int heuristic, int k) {
  const int len = t.size();
  removed_.clear();
  auto take = [&](int set) {
    drop_[set] = 1;
    removed_.push_back(set);
  };
  switch (heuristic) {
    case 0: {  // random
      order_.resize(len);
      for (int i = 0; i < len; ++i) order_[i] = i;
      for (int i = 0; i < k; ++i) {
        std::swap(order_[i], order_[i + rng_.UniformInt(len - i)]);
        take(p_.set_of[t.seq[order_[i]]]);
      }
      break;
    }
    case 1: {  // worst: largest saving when removed, rank-biased, updated as we go
      link_prev_.resize(len);
      link_next_.resize(len);
      gain_.resize(len);
      idx_.resize(len);
      auto gain = [&](int i) {
        const int a = t.seq[link_prev_[i]], v = t.seq[i], b = t.seq[link_next_[i]];
        return p_.c(a, v) + p_.c(v, b) - p_.c(a, b);
      };
      for (int i = 0; i < len; ++i) {
        link_prev_[i] = t.prev(i);
        link_next_[i] = t.next(i);
        idx_[i] = i;
      }
      for (int i = 0; i < len; ++i) gain_[i] = gain(i);
      for (int step = 0; step < k; ++step) {
        const int cnt = static_cast<int>(idx_.size());
        const int j =
            std::min(cnt - 1, static_cast<int>(std::pow(rng_.Uniform(), kRemovalPower) * cnt));
        std::nth_element(idx_.begin(), idx_.begin() + j, idx_.end(),
                         [&](int x, int y) { return gain_[x] > gain_[y]; });
        const int i = idx_[j];
        idx_[j] = idx_.back();
        idx_.pop_back();
        take(p_.set_of[t.seq[i]]);
        const int pr = link_prev_[i], nx = link_next_[i];
        link_next_[pr] = nx;
        link_prev_[nx] = pr;
        gain_[pr] = gain(pr);
        gain_[nx] = gain(nx);
      }
      break;
    }
    case 2: {  // segment
      const int start = rng_.UniformInt(len);
      for (int i = 0; i < k; ++i) take(p_.set_of[t.seq[(start + i) % len]]);
      break;
    }
    default: {  // distance: grow a cluster of mutually close sets
      take(p_.set_of[t.seq[rng_.UniformInt(len)]]);
      int cand[kDistanceCandidates];
      while (static_cast<int>(removed_.size()) < k) {
        const int r = removed_[rng_.UniformInt(static_cast<int>(removed_.size()))];
        int cnt = 0;
        for (int s : p_.near_sets[r]) {
          if (t.pos[s] >= 0 && !drop_[s]) {
            cand[cnt++] = s;
            if (cnt == kDistanceCandidates) break;
          }
        }
        if (cnt > 0) {
          take(cand[std::min(cnt - 1,
                             static_cast<int>(std::pow(rng_.Uniform(), kRemovalPower) * cnt))]);
        } else {
          int s = p_.set_of[t.seq[rng_.UniformInt(len)]];
          while (drop_[s]) s = p_.set_of[t.seq[rng_.UniformInt(len)]];
          take(s);
        }
      }
      break;
    }
  }
  t.RemoveSets(p_, drop_);
  for (int s : removed_) drop_[s] = 0;
}

void LnsTrial::Construct(SearchTour& t, int mode) {
  t.Reset(p_);
  removed_.resize(p_.m);
  for (int s = 0; s < p_.m; ++s) removed_[s] = s;
  InsertSets(t, mode, 0.0);
  t.RecomputeCost(p_);
}

TrialOutcome LnsTrial::Run(const SearchTour* start, const StopToken& stop,
                           const std::function<void(const SearchTour&)>& on_best) {
  TrialOutcome out;
  SearchTour current;
  if (start != nullptr) {
    current = *start;
  } else {
    Construct(current, kRandomOrder);
  }
  LocalOptimize(current, stop);
  out.best = current;
  if (on_best) on_best(out.best);
  if (p_.m <= 1) return out;

  const absl::Time t0 = absl::Now();
  const bool timed = params_.time_budget_end != absl::InfiniteFuture();
  const double budget_s =
      timed ? std::max(1e-3, absl::ToDoubleSeconds(params_.time_budget_end - t0)) : 1.0;
  // Small instances still need room to move: at least 5 removals (or m-1).
  const int kmax = std::max(
      1,
      std::min({p_.m - 1, params_.max_removals_cap,
                std::max(5, static_cast<int>(std::lround(params_.max_removal_fraction * p_.m)))}));
  // A warm start is already good: begin cooler so as not to throw it away.
  const double accept_start =
      params_.accept_start * (start != nullptr ? params_.warm_start_factor : 1.0);
  const double log_ratio = std::log(params_.accept_end / accept_start);
  int64_t half_way = 0;
  SearchTour cand;
  int64_t last_improvement = 0;
  for (int64_t it = 0;; ++it) {
    if (stop.ShouldStop()) {
      out.stopped = true;
      break;
    }
    double progress = static_cast<double>(it) / static_cast<double>(params_.max_iterations);
    if (timed) progress = std::max(progress, absl::ToDoubleSeconds(absl::Now() - t0) / budget_s);
    if (progress >= 1.0) break;
    // Stagnation only counts in the cool half: a hot start rarely beats the
    // best tour (warm starts begin at it).
    if (progress < 0.5) {
      half_way = it;
    } else if (it - std::max(last_improvement, half_way) > params_.stall_iterations) {
      break;
    }
    ++out.iterations;
    const double accept_frac = accept_start * std::exp(log_ratio * progress);
    const double temperature = accept_frac * current.cost / std::log(2.0);

    const int r = Roulette(removal_weight_, kNumRemovals);
    const int h = Roulette(insertion_weight_, kNumInsertions);
    const int k = rng_.UniformInt(1, kmax);
    cand.seq = current.seq;
    cand.pos = current.pos;
    cand.cost = current.cost;
    Remove(cand, r, k);
    touched_.assign(removed_.begin(), removed_.end());
    InsertSets(cand, h % 3, kNoiseLevels[h / 3]);
    cand.RecomputeCost(p_);
    if (cand.cost < out.best.cost * (1.0 + params_.local_window) ||
        rng_.Uniform() < params_.local_probability) {
      local_.Run(cand, &touched_, stop);
    }

    double score = 0.0;
    if (cand.cost < current.cost - Eps(current.cost)) {
      score = kScoreBetter;
      std::swap(current, cand);
      if (current.cost < out.best.cost - Eps(out.best.cost)) {
        score = kScoreBest;
        out.best = current;
        last_improvement = it;
        if (on_best) on_best(out.best);
      }
    } else if (rng_.Uniform() <
               std::exp(-(cand.cost - current.cost) / std::max(temperature, 1e-300))) {
      score = kScoreAccepted;
      std::swap(current, cand);
    }
    removal_score_[r] += score;
    insertion_score_[h] += score;
    ++removal_uses_[r];
    ++insertion_uses_[h];
    if ((it + 1) % kWeightPeriod == 0) {
      auto update = [](double* w, double* sc, int* uses, int count) {
        for (int i = 0; i < count; ++i) {
          if (uses[i] > 0) w[i] = (1 - kWeightReaction) * w[i] + kWeightReaction * sc[i] / uses[i];
          w[i] = std::max(w[i], 0.02);
          sc[i] = 0.0;
          uses[i] = 0;
        }
      };
      update(removal_weight_, removal_score_, removal_uses_, kNumRemovals);
      update(insertion_weight_, insertion_score_, insertion_uses_, kNumInsertions);
    }
  }
  return out;
}

}  // namespace covplan::gtsp_internal
