#include "planner/tour/gtsp/gtsp.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>

#include "absl/strings/str_cat.h"
#include "planner/common/status_macros.h"
#include "planner/tour/gtsp/gtsp_memetic.h"
#include "planner/tour/gtsp/gtsp_problem.h"
#include "planner/tour/gtsp/gtsp_search.h"
#include "planner/tour/gtsp/rng.h"

namespace covplan {
namespace {

using gtsp_internal::LnsTrial;
using gtsp_internal::MemeticSearch;
using gtsp_internal::Problem;
using gtsp_internal::SearchParams;
using gtsp_internal::SearchTour;
using gtsp_internal::SeedFor;
using gtsp_internal::TrialOutcome;

// The hybrid search: the memetic search's share of the deadline (0.3, 0.5,
// 0.7 and 0.8 tried, docs/benchmarks-archive.md §4), the warm LNS trials that
// follow it and the seed range of chained LNS trials.
constexpr double kMemeticShare = 0.8;
constexpr int kPolishTrials = 4;
constexpr uint64_t kChainSeeds = 1 << 20;

struct EffortConfig {
  int trials;       // when neither max_trials nor "until deadline" applies
  int cold_trials;  // trials started from a fresh random tour
  int64_t iterations_per_set;
  int64_t stall_per_set;
  int64_t min_iterations;
};

EffortConfig ConfigFor(GtspEffort effort) {
  switch (effort) {
    case GtspEffort::kFast:
      return {2, 1, 12, 10, 3000};
    case GtspEffort::kDefault:
      return {5, 2, 60, 30, 5000};
    case GtspEffort::kThorough:
      return {10, 3, 150, 60, 10000};
  }
  return {5, 2, 60, 30, 5000};
}

SearchTour ToSearchTour(const Problem& p, const std::vector<int>& tour) {
  SearchTour t;
  t.Reset(p);
  for (int v : tour) t.seq.push_back(p.to_internal[v]);
  t.RebuildPositions(p);
  t.RecomputeCost(p);
  return t;
}

// Runs run(0..count-1), in parallel threads unless count is 1.
void RunParallel(int count, const std::function<void(int)>& run) {
  if (count == 1) {
    run(0);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(count);
  for (int j = 0; j < count; ++j) pool.emplace_back(run, j);
  for (std::thread& th : pool) th.join();
}

// One SolveGtsp call: the problem, the best tour so far and the tallies of
// the searches run on it. The searches of one round (or the threads' chains
// and searches) run in parallel, read best_ only and call ReportBest
// concurrently (it locks); Take and Finish run on the solving thread.
class GtspSolve {
 public:
  GtspSolve(const GtspInstance& instance, const GtspOptions& options)
      : instance_(instance),
        options_(options),
        t_start_(absl::Now()),
        problem_(Problem::Build(instance)),
        cfg_(ConfigFor(options.effort)) {
    params_.max_iterations =
        std::max<int64_t>(cfg_.min_iterations, cfg_.iterations_per_set * problem_.m);
    params_.stall_iterations =
        std::max<int64_t>(cfg_.min_iterations / 2, cfg_.stall_per_set * problem_.m);
    on_best_ = [this](const SearchTour& t) { ReportBest(t); };
  }

  GtspResult Solve() {
    GreedyStart();
    // kThorough with a deadline (and no trial limit) uses all the time
    // given: per thread one memetic search (its own population, seeded with
    // the tour so far), then, in the hybrid, LNS trials from its best tour
    // (docs/benchmarks.md, section 4).
    const bool until_deadline = options_.max_trials == 0 && options_.stop.has_deadline() &&
                                options_.effort == GtspEffort::kThorough;
    if (until_deadline && options_.search != GtspSearch::kLns) {
      RunUntilDeadline();
    } else {
      RunTrials();
    }
    return Finish();
  }

 private:
  // Shared best, only for progress reporting; the returned tour is chosen
  // deterministically from the per-trial results (Take).
  void ReportBest(const SearchTour& t) {
    std::lock_guard<std::mutex> lock(mu_);
    if (t.cost >= reported_cost_) return;
    reported_cost_ = t.cost;
    time_to_best_ = absl::ToDoubleSeconds(absl::Now() - t_start_);
    if (options_.on_improvement) options_.on_improvement(t.cost, time_to_best_);
  }

  // A greedy tour first, so that there is always an answer.
  void GreedyStart() {
    LnsTrial greedy(problem_, params_, SeedFor(options_.seed, 0xFFFFFFFFull));
    greedy.Construct(best_, /*mode=cheapest*/ 0);
    if (!options_.initial_tour.empty()) {
      SearchTour init = ToSearchTour(problem_, options_.initial_tour);
      if (init.cost <= best_.cost) best_ = init;
    }
    if (!options_.stop.ShouldStop()) greedy.LocalOptimize(best_, options_.stop);
    ReportBest(best_);
  }

  // Folds the threads' outcomes into the result; `completed[j]`, if given,
  // is how many trials thread j completed (otherwise one unless stopped).
  void Take(std::vector<TrialOutcome>& outcomes, const std::vector<int>* completed = nullptr) {
    for (size_t j = 0; j < outcomes.size(); ++j) {
      TrialOutcome& o = outcomes[j];
      result_.iterations += o.iterations;
      if (o.stopped) result_.stopped_early = true;
      if (completed != nullptr) {
        result_.trials_completed += (*completed)[j];
      } else if (!o.stopped) {
        ++result_.trials_completed;
      }
      if (gtsp_internal::Cheaper(o.best.cost, best_.cost)) best_ = std::move(o.best);
    }
  }

  // One search per thread until the deadline. Thread j's search depends
  // only on (seed, j) and the clock, and thread 0 runs the one-thread
  // search, so with a core per thread more threads only add tours to choose
  // from (issue 31: two threads at equal wall time never worse than one;
  // with fewer cores than threads, thread 0 gets less CPU). Odd threads
  // racing the LNS trials instead did worse at 2 threads
  // (docs/benchmarks-archive.md §4).
  void RunUntilDeadline() {
    const StopToken& stop = options_.stop;
    if (problem_.m <= 1) return;
    if (stop.ShouldStop()) {
      result_.stopped_early = true;  // stopped before the search began
      return;
    }
    const absl::Time now = absl::Now();
    const absl::Time deadline = stop.deadline();
    const bool hybrid = options_.search == GtspSearch::kHybrid;
    SearchParams memetic_params = params_;
    memetic_params.time_budget_end = hybrid ? now + (deadline - now) * kMemeticShare : deadline;
    const int threads = options_.num_threads;
    std::vector<TrialOutcome> outcomes(threads);
    std::vector<int> completed(threads, 0);
    const SearchTour warm = best_;
    RunParallel(threads, [&](int j) {
      MemeticSearch search(problem_, memetic_params, SeedFor(options_.seed, j));
      outcomes[j] = search.Run(&warm, stop, on_best_);
      // Up to two sets the memetic search's local step is exact: nothing to
      // polish, and no reason to wait for the deadline.
      if (hybrid && problem_.m > 2) {
        completed[j] =
            LnsChain(ChainSeeds(j), deadline, kPolishTrials, 0, /*fill=*/true, outcomes[j]);
      } else {
        completed[j] = outcomes[j].stopped ? 0 : 1;
      }
    });
    Take(outcomes, &completed);
  }

  // Seeds of thread j's chained trials (thread 0's are the trial indices, as
  // in the rounds of RunTrials).
  static uint64_t ChainSeeds(int thread) {
    return thread == 0 ? 0 : kChainSeeds + (static_cast<uint64_t>(thread) << 16);
  }

  // LNS trials in a chain from `out.best`, each from the chain's best so far
  // (the first `cold` from a random tour instead), seeded from `seeds` on:
  // `trials` of them with the time left to `deadline` spread over them, and
  // with `fill` more until the deadline (a trial that stalls early leaves
  // its time to the next). Returns the trials completed.
  // After the memetic search (the hybrid's second part): the memetic search
  // converges on the arcs its population shares; the LNS's annealing removes
  // and re-inserts whole regions of one tour and finds what those arcs hide.
  int LnsChain(uint64_t seeds, absl::Time deadline, int trials, int cold, bool fill,
               TrialOutcome& out) {
    const StopToken& stop = options_.stop;
    int t = 0, completed = 0;
    bool cut = false;  // a trial was cut short by the StopToken
    for (; (fill || t < trials) && !stop.ShouldStop(); ++t) {
      const absl::Time now = absl::Now();
      if (now >= deadline) break;
      SearchParams params = params_;
      params.time_budget_end = now + (deadline - now) / std::max(1, trials - t);
      LnsTrial lns(problem_, params, SeedFor(options_.seed, seeds + t));
      TrialOutcome o = lns.Run(t < cold ? nullptr : &out.best, stop, on_best_);
      out.iterations += o.iterations;
      if (o.stopped) {
        cut = true;
      } else {
        ++completed;
      }
      if (gtsp_internal::Cheaper(o.best.cost, out.best.cost)) out.best = std::move(o.best);
    }
    // Filling until the deadline always ends stopped (as the memetic search).
    out.stopped = fill ? stop.ShouldStop() : cut || t < trials;
    return completed;
  }

  // The trials of the effort, or max_trials; 0 for none.
  int EffortTrials() const {
    if (problem_.m <= 1 || options_.max_trials == GtspOptions::kLocalStepOnly) return 0;
    return options_.max_trials > 0 ? options_.max_trials : cfg_.trials;
  }

  // With a deadline, every thread runs the one-thread sequence of trials in
  // a chain (thread 0 with the one-thread seeds), the time spread over its
  // trials: two threads are never worse than one (issue 31). Without one,
  // the trials run in whole rounds of `num_threads` parallel trials, each
  // round from the best so far (deterministic for a seed and thread count):
  // a last round with fewer trials than threads would cost a full trial of
  // wall time with cores idle, so it is dropped (at least one round runs).
  void RunTrials() {
    const StopToken& stop = options_.stop;
    const int threads = options_.num_threads;
    const int trials = EffortTrials();
    if (trials == 0) return;
    const int cold = options_.initial_tour.empty() ? cfg_.cold_trials : 0;
    if (stop.has_deadline()) {
      std::vector<TrialOutcome> outcomes(threads);
      std::vector<int> completed(threads, 0);
      RunParallel(threads, [&](int j) {
        outcomes[j].best = best_;
        completed[j] = LnsChain(ChainSeeds(j), stop.deadline(), trials, cold, false, outcomes[j]);
      });
      Take(outcomes, &completed);
      return;
    }
    const int total_trials =
        options_.max_trials > 0 ? trials : std::max(1, trials / threads) * threads;
    int started = 0;
    while (started < total_trials && !stop.ShouldStop()) {
      const int round = std::min(threads, total_trials - started);
      std::vector<TrialOutcome> outcomes(round);
      const SearchTour warm = best_;
      RunParallel(round, [&](int j) {
        const int trial = started + j;
        LnsTrial lns(problem_, params_, SeedFor(options_.seed, trial));
        outcomes[j] = lns.Run(trial < cold ? nullptr : &warm, stop, on_best_);
      });
      Take(outcomes);
      started += round;
    }
    if (started < total_trials) result_.stopped_early = true;
  }

  GtspResult Finish() {
    result_.tour.reserve(best_.seq.size());
    for (int v : best_.seq) result_.tour.push_back(problem_.to_external[v]);
    result_.cost = TourCost(instance_, result_.tour);
    result_.elapsed_s = absl::ToDoubleSeconds(absl::Now() - t_start_);
    result_.time_to_best_s = time_to_best_;
    return std::move(result_);
  }

  const GtspInstance& instance_;
  const GtspOptions& options_;
  const absl::Time t_start_;
  const Problem problem_;
  const EffortConfig cfg_;
  SearchParams params_;
  std::function<void(const SearchTour&)> on_best_;  // ReportBest
  SearchTour best_;
  GtspResult result_;
  std::mutex mu_;
  double reported_cost_ = std::numeric_limits<double>::infinity();  // guarded by mu_
  double time_to_best_ = 0.0;                                       // guarded by mu_
};

}  // namespace

absl::Status GtspInstance::Validate() const {
  if (num_vertices <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("GTSP instance needs at least one vertex, got num_vertices=", num_vertices));
  }
  const size_t expected = static_cast<size_t>(num_vertices) * num_vertices;
  if (costs.size() != expected) {
    return absl::InvalidArgumentError(absl::StrCat(
        "GTSP cost matrix has ", costs.size(), " entries, expected num_vertices^2 = ", expected));
  }
  if (sets.empty()) return absl::InvalidArgumentError("GTSP instance has no sets");
  std::vector<int> owner(num_vertices, -1);
  for (size_t s = 0; s < sets.size(); ++s) {
    if (sets[s].empty())
      return absl::InvalidArgumentError(absl::StrCat("GTSP set ", s, " is empty"));
    for (int v : sets[s]) {
      if (v < 0 || v >= num_vertices) {
        return absl::InvalidArgumentError(absl::StrCat("GTSP set ", s, " contains vertex ", v,
                                                       ", outside [0, ", num_vertices, ")"));
      }
      if (owner[v] >= 0) {
        return absl::InvalidArgumentError(absl::StrCat("vertex ", v, " is in GTSP set ", owner[v],
                                                       " and in set ", s,
                                                       "; sets must be disjoint"));
      }
      owner[v] = static_cast<int>(s);
    }
  }
  for (int v = 0; v < num_vertices; ++v) {
    if (owner[v] < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("vertex ", v, " belongs to no GTSP set; sets must partition the vertices"));
    }
  }
  for (size_t k = 0; k < costs.size(); ++k) {
    const double c = costs[k];
    if (!std::isfinite(c) || c < 0.0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "GTSP cost(", k / num_vertices, ", ", k % num_vertices, ") = ", c,
          " is not a finite non-negative number (use kInfeasibleCost for forbidden arcs)"));
    }
  }
  return absl::OkStatus();
}

absl::Status GtspOptions::Validate() const {
  if (num_threads < 1 || num_threads > 256) {
    return absl::InvalidArgumentError(
        absl::StrCat("num_threads must be in [1, 256], got ", num_threads));
  }
  if (max_trials < GtspOptions::kLocalStepOnly) {
    return absl::InvalidArgumentError(absl::StrCat("max_trials must be >= -1, got ", max_trials));
  }
  return absl::OkStatus();
}

double TourCost(const GtspInstance& instance, const std::vector<int>& tour) {
  double total = 0.0;
  for (size_t i = 0; i < tour.size(); ++i) {
    total += instance.cost(tour[i], tour[(i + 1) % tour.size()]);
  }
  return total;
}

absl::Status ValidateTour(const GtspInstance& instance, const std::vector<int>& tour) {
  if (tour.size() != instance.sets.size()) {
    return absl::InvalidArgumentError(absl::StrCat("tour visits ", tour.size(),
                                                   " vertices, expected one per set (",
                                                   instance.sets.size(), ")"));
  }
  std::vector<int> owner(instance.num_vertices, -1);
  for (size_t s = 0; s < instance.sets.size(); ++s) {
    for (int v : instance.sets[s]) {
      if (v >= 0 && v < instance.num_vertices) owner[v] = static_cast<int>(s);
    }
  }
  std::vector<char> seen(instance.sets.size(), 0);
  for (int v : tour) {
    if (v < 0 || v >= instance.num_vertices) {
      return absl::InvalidArgumentError(
          absl::StrCat("tour vertex ", v, " out of range [0, ", instance.num_vertices, ")"));
    }
    const int s = owner[v];
    if (s < 0) return absl::InvalidArgumentError(absl::StrCat("tour vertex ", v, " is in no set"));
    if (seen[s]) return absl::InvalidArgumentError(absl::StrCat("tour visits set ", s, " twice"));
    seen[s] = 1;
  }
  return absl::OkStatus();
}

absl::StatusOr<GtspResult> SolveGtsp(const GtspInstance& instance, const GtspOptions& options) {
  RETURN_IF_ERROR(instance.Validate());
  RETURN_IF_ERROR(options.Validate());
  if (!options.initial_tour.empty()) {
    absl::Status st = ValidateTour(instance, options.initial_tour);
    if (!st.ok()) return absl::InvalidArgumentError(absl::StrCat("initial_tour: ", st.message()));
  }
  return GtspSolve(instance, options).Solve();
}

}  // namespace covplan
