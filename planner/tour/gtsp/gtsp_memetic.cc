#include "planner/tour/gtsp/gtsp_memetic.h"

#include <algorithm>
#include <cmath>

#include "absl/time/clock.h"

namespace covplan::gtsp_internal {
namespace {

constexpr double kMutationProbability = 0.1;
// Filling the population (at the start and on a restart) stops once this
// share of the time left is spent (a large instance with a short budget
// evolves a smaller population).
constexpr double kInitialShare = 0.25;
constexpr int kKeptOnRestart = 2;
constexpr int kRandomOrder = 2;  // LnsTrial::Construct mode

bool SameCost(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(a)); }

}  // namespace

MemeticSearch::MemeticSearch(const Problem& p, const SearchParams& params, uint64_t seed)
    : p_(p), params_(params), rng_(seed), local_(p), builder_(p, params, SeedFor(seed, 1)) {
  taken_.assign(p.m, 0);
}

void MemeticSearch::Crossover(const SearchTour& a, const SearchTour& b, SearchTour& child) {
  const int m = a.size();
  child.Reset(p_);
  const int start = rng_.UniformInt(m);
  const int len = rng_.UniformInt(std::max(1, m / 10), std::max(1, 2 * m / 3));
  std::fill(taken_.begin(), taken_.end(), 0);
  for (int i = 0; i < len; ++i) {
    const int v = a.seq[(start + i) % m];
    child.seq.push_back(v);
    taken_[p_.set_of[v]] = 1;
  }
  const int after = b.pos[p_.set_of[child.seq.back()]];
  for (int i = 1; i <= m; ++i) {
    const int v = b.seq[(after + i) % m];
    if (!taken_[p_.set_of[v]]) child.seq.push_back(v);
  }
  child.RebuildPositions(p_);
  child.RecomputeCost(p_);
}

void MemeticSearch::Mutate(SearchTour& t) {
  const int m = t.size();
  int i = rng_.UniformInt(m), j = rng_.UniformInt(m);
  if (i > j) std::swap(i, j);
  if (j - i < 2) return;
  std::reverse(t.seq.begin() + i, t.seq.begin() + j);
  t.RebuildPositions(p_, i);
  t.RecomputeCost(p_);
}

int MemeticSearch::Tournament(int size) {
  return std::min(rng_.UniformInt(size), rng_.UniformInt(size));  // the population is sorted
}

void MemeticSearch::AddRandomTour(std::vector<SearchTour>& pop, const StopToken& stop) {
  SearchTour t;
  builder_.Construct(t, kRandomOrder);
  local_.Run(t, nullptr, stop);
  pop.push_back(std::move(t));
}

void MemeticSearch::Select(std::vector<SearchTour>& pop) {
  std::sort(pop.begin(), pop.end(),
            [](const SearchTour& x, const SearchTour& y) { return x.cost < y.cost; });
  size_t kept = 0;
  for (size_t i = 0; i < pop.size() && kept < static_cast<size_t>(kPopulation); ++i) {
    if (kept > 0 && SameCost(pop[i].cost, pop[kept - 1].cost)) continue;
    if (kept != i) pop[kept] = std::move(pop[i]);
    ++kept;
  }
  pop.resize(kept);
}

TrialOutcome MemeticSearch::Run(const SearchTour* start, const StopToken& stop,
                                const std::function<void(const SearchTour&)>& on_best) {
  TrialOutcome out;
  const absl::Time end = params_.time_budget_end;
  auto time_left = [&] { return !stop.ShouldStop() && absl::Now() < end; };

  std::vector<SearchTour> pop;
  if (start != nullptr) {
    pop.push_back(*start);
    local_.Run(pop.back(), nullptr, stop);
  } else {
    AddRandomTour(pop, stop);
  }
  out.best = pop[0];
  if (on_best) on_best(out.best);
  if (p_.m <= 2) {  // one order up to rotation; LocalSearch's vertex re-selection is exact
    out.stopped = stop.ShouldStop();
    return out;
  }
  // The population is sorted: takes its first tour if it beats the best.
  auto take_best = [&] {
    if (!Cheaper(pop[0].cost, out.best.cost)) return false;
    out.best = pop[0];
    if (on_best) on_best(out.best);
    return true;
  };
  // Adds fresh local optima up to kPopulation, for at most kInitialShare of
  // the time left (at least two tours in all).
  auto fill = [&] {
    const absl::Time now = absl::Now();
    const absl::Time until =
        end == absl::InfiniteFuture() ? end : now + (end - now) * kInitialShare;
    while (static_cast<int>(pop.size()) < kPopulation && time_left() &&
           (pop.size() < 2 || absl::Now() < until)) {
      AddRandomTour(pop, stop);
    }
    Select(pop);
    take_best();
  };
  fill();

  std::vector<SearchTour> children;
  int stale = 0;
  while (time_left()) {
    const int size = static_cast<int>(pop.size());
    children.resize(kPopulation);
    int made = 0;
    for (; made < kPopulation && time_left(); ++made) {
      const int a = Tournament(size);
      int b = Tournament(size);
      if (b == a && size > 1) b = (a + 1) % size;
      SearchTour& child = children[made];
      Crossover(pop[a], pop[b], child);
      if (rng_.Uniform() < kMutationProbability) Mutate(child);
      ClusterOptimize(p_, child, cluster_scratch_);
      local_.Run(child, nullptr, stop);
      ++out.iterations;
    }
    for (int i = 0; i < made; ++i) pop.push_back(std::move(children[i]));
    Select(pop);
    if (take_best()) {
      stale = 0;
    } else if (++stale >= kStaleGenerations) {
      // Converged: keep the best and refill with fresh local optima.
      stale = 0;
      pop.resize(std::min<size_t>(pop.size(), kKeptOnRestart));
      fill();
    }
  }
  out.stopped = stop.ShouldStop();
  return out;
}

}  // namespace covplan::gtsp_internal
