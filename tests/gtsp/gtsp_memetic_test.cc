// The memetic search that fills a thorough solve's deadline: its crossover
// builds valid children from both parents, a run returns the best tour it
// reported, and through SolveGtsp it finds the Held-Karp optimum of small
// instances with one and two threads.
#include <algorithm>
#include <numeric>
#include <vector>

#include "absl/time/clock.h"
#include "gtest/gtest.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/gtsp/gtsp_memetic.h"
#include "planner/tour/gtsp/gtsp_problem.h"
#include "planner/tour/gtsp/rng.h"
#include "tests/gtsp/gtsp_test_util.h"

namespace covplan {
namespace {

using gtsp_internal::MemeticSearch;
using gtsp_internal::Problem;
using gtsp_internal::SearchParams;
using gtsp_internal::SearchTour;
using gtsp_internal::TrialOutcome;
using testing_gtsp::HeldKarpOptimum;
using testing_gtsp::kAsymmetric;
using testing_gtsp::kEuclidean;
using testing_gtsp::RandomInstance;

// A random order of the sets with a random vertex of each.
SearchTour RandomTour(const Problem& p, gtsp_internal::Rng& rng) {
  std::vector<int> sets(p.m);
  std::iota(sets.begin(), sets.end(), 0);
  for (int i = p.m - 1; i > 0; --i) std::swap(sets[i], sets[rng.UniformInt(i + 1)]);
  SearchTour t;
  t.Reset(p);
  for (int s : sets) t.seq.push_back(p.set_begin[s] + rng.UniformInt(p.set_size(s)));
  t.RebuildPositions(p);
  t.RecomputeCost(p);
  return t;
}

bool IsFullTour(const Problem& p, const SearchTour& t) {
  if (t.size() != p.m) return false;
  std::vector<int> seen(p.m, 0);
  for (int i = 0; i < t.size(); ++i) {
    const int s = p.set_of[t.seq[i]];
    if (seen[s]++ > 0 || t.pos[s] != i) return false;
  }
  return true;
}

TEST(MemeticTest, CrossoverKeepsAFragmentOfOneParentAndTheOrderOfTheOther) {
  const GtspInstance inst = RandomInstance(5, 40, 3, kAsymmetric);
  const Problem p = Problem::Build(inst);
  gtsp_internal::Rng rng(17);
  SearchParams params;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    MemeticSearch search(p, params, seed);
    const SearchTour a = RandomTour(p, rng), b = RandomTour(p, rng);
    SearchTour child;
    search.Crossover(a, b, child);
    ASSERT_TRUE(IsFullTour(p, child)) << "seed " << seed;
    double cost = 0.0;
    for (int i = 0; i < child.size(); ++i) cost += p.c(child.seq[i], child.seq[child.next(i)]);
    EXPECT_NEAR(child.cost, cost, 1e-6);

    // The child is, for one fragment length in [m/10, 2m/3], that many sets
    // of `a` from where the child begins, then the other sets in b's cyclic
    // order from the set after the fragment's last one, with b's vertices.
    const int from = a.pos[p.set_of[child.seq[0]]];
    bool matched = false;
    for (int len = std::max(1, p.m / 10); len <= std::max(1, 2 * p.m / 3) && !matched; ++len) {
      std::vector<int> expected;
      std::vector<char> taken(p.m, 0);
      for (int i = 0; i < len; ++i) {
        expected.push_back(a.seq[(from + i) % p.m]);
        taken[p.set_of[expected.back()]] = 1;
      }
      const int after = b.pos[p.set_of[expected.back()]];
      for (int i = 1; i <= p.m; ++i) {
        const int v = b.seq[(after + i) % p.m];
        if (!taken[p.set_of[v]]) expected.push_back(v);
      }
      matched = expected == child.seq;
    }
    EXPECT_TRUE(matched) << "seed " << seed
                         << ": the child is no fragment of a followed by b's order";
  }
}

TEST(MemeticTest, RunReturnsTheLastTourItReportedAndNeverWorseThanItsStart) {
  const GtspInstance inst = RandomInstance(9, 60, 4, kEuclidean, 2);
  const Problem p = Problem::Build(inst);
  gtsp_internal::Rng rng(3);
  const SearchTour start = RandomTour(p, rng);
  SearchParams params;
  params.time_budget_end = absl::Now() + absl::Milliseconds(60);
  MemeticSearch search(p, params, 11);
  std::vector<double> reported;
  const TrialOutcome out = search.Run(&start, StopToken(), [&](const SearchTour& t) {
    EXPECT_TRUE(IsFullTour(p, t));
    reported.push_back(t.cost);
  });
  ASSERT_TRUE(IsFullTour(p, out.best));
  ASSERT_FALSE(reported.empty());
  EXPECT_TRUE(std::is_sorted(reported.rbegin(), reported.rend()));  // each report improves
  EXPECT_DOUBLE_EQ(out.best.cost, reported.back());
  EXPECT_LT(out.best.cost, start.cost);  // a random tour of 60 sets is far from locally optimal
  EXPECT_GT(out.iterations, 0);
}

// Every search that fills a deadline: the hybrid (the default), the LNS
// trials and the memetic search alone.
TEST(MemeticTest, EveryDeadlineSearchFindsTheHeldKarpOptimum) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    // 2 and 3 sets, then 3..10.
    const int num_sets = seed <= 2 ? 1 + static_cast<int>(seed) : 3 + static_cast<int>(seed % 8);
    const GtspInstance inst =
        RandomInstance(seed, num_sets, 3, seed % 2 ? kAsymmetric : kEuclidean, 2);
    const double opt = HeldKarpOptimum(inst);
    for (GtspSearch search : {GtspSearch::kHybrid, GtspSearch::kLns, GtspSearch::kMemetic}) {
      for (int threads : {1, 2}) {
        GtspOptions options;
        options.seed = seed;
        options.num_threads = threads;
        options.effort = GtspEffort::kThorough;
        options.search = search;
        options.stop = StopToken::WithTimeout(absl::Milliseconds(60));
        absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
        ASSERT_TRUE(r.ok()) << r.status();
        ASSERT_TRUE(ValidateTour(inst, r->tour).ok());
        EXPECT_NEAR(r->cost, opt, 1e-6)
            << "seed " << seed << ", " << num_sets << " sets, " << threads << " threads, search "
            << static_cast<int>(search);
        if (num_sets > 2) {
          EXPECT_GT(r->iterations, 0);  // the search ran, not only the greedy step
        } else if (search != GtspSearch::kLns) {
          // Exact after the local step: returns without waiting for the deadline.
          EXPECT_FALSE(r->stopped_early)
              << "seed " << seed << ", search " << static_cast<int>(search);
          EXPECT_EQ(r->trials_completed, threads);
        }
      }
    }
  }
}

}  // namespace
}  // namespace covplan
