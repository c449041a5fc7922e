// Solver correctness: valid tours, exact optima on small generated instances
// (checked against Held-Karp), determinism, input validation.
#include <cmath>
#include <limits>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/tour/gtsp/gtsp.h"
#include "tests/gtsp/gtsp_test_util.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;
using testing_gtsp::HeldKarpOptimum;
using testing_gtsp::kAsymmetric;
using testing_gtsp::kEuclidean;
using testing_gtsp::RandomInstance;

void ExpectValidResult(const GtspInstance& inst, const GtspResult& r) {
  ASSERT_TRUE(ValidateTour(inst, r.tour).ok()) << ValidateTour(inst, r.tour);
  EXPECT_DOUBLE_EQ(r.cost, TourCost(inst, r.tour));
}

struct ExactCase {
  testing_gtsp::CostKind kind;
  const char* name;
};

class ExactOptimumTest : public ::testing::TestWithParam<ExactCase> {};

TEST_P(ExactOptimumTest, MatchesHeldKarpOnRandomInstances) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const int num_sets = 3 + static_cast<int>(seed % 7);  // 3..9 sets
    const GtspInstance inst = RandomInstance(seed, num_sets, 3, GetParam().kind);
    const double opt = HeldKarpOptimum(inst);
    GtspOptions opt_options;
    opt_options.seed = seed;
    absl::StatusOr<GtspResult> r = SolveGtsp(inst, opt_options);
    ASSERT_TRUE(r.ok()) << r.status();
    ExpectValidResult(inst, *r);
    EXPECT_NEAR(r->cost, opt, 1e-6) << "seed " << seed << ", " << num_sets << " sets";
    EXPECT_FALSE(r->stopped_early);
    EXPECT_GT(r->trials_completed, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, ExactOptimumTest,
                         ::testing::Values(ExactCase{kEuclidean, "Symmetric"},
                                           ExactCase{kAsymmetric, "Asymmetric"}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(GtspSolverTest, FastEffortAlsoExactOnSmallAsymmetric) {
  for (unsigned seed = 100; seed < 106; ++seed) {
    const GtspInstance inst = RandomInstance(seed, 9, 3, kAsymmetric, /*min_set_size=*/2);
    GtspOptions options;
    options.effort = GtspEffort::kFast;
    options.seed = seed;
    absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_NEAR(r->cost, HeldKarpOptimum(inst), 1e-6) << "seed " << seed;
  }
}

TEST(GtspSolverTest, OneSetPicksCheapestSelfLoop) {
  GtspInstance inst;
  inst.num_vertices = 3;
  inst.costs = {5, 1, 1, 1, 2, 1, 1, 1, 7};
  inst.sets = {{0, 1, 2}};
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, {});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->tour, std::vector<int>({1}));
  EXPECT_DOUBLE_EQ(r->cost, 2.0);
}

TEST(GtspSolverTest, TwoSetsAsymmetric) {
  // Sets {0,1} and {2,3}; the cheapest round trip is 1 -> 3 -> 1 (cost 2+3).
  GtspInstance inst;
  inst.num_vertices = 4;
  inst.costs = {0, 9, 4, 8,  //
                9, 0, 6, 2,  //
                4, 9, 0, 9,  //
                9, 3, 9, 0};
  inst.sets = {{0, 1}, {2, 3}};
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, {});
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectValidResult(inst, *r);
  EXPECT_DOUBLE_EQ(r->cost, 5.0);
  EXPECT_DOUBLE_EQ(r->cost, HeldKarpOptimum(inst));
}

TEST(GtspSolverTest, AvoidsInfeasibleArcsWhenPossible) {
  GtspInstance inst = RandomInstance(5, 8, 2, kEuclidean);
  // Forbid every arc leaving vertex 0 towards odd vertices.
  for (int j = 1; j < inst.num_vertices; j += 2) {
    inst.costs[j] = GtspInstance::kInfeasibleCost;
  }
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, {});
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectValidResult(inst, *r);
  EXPECT_LT(r->cost, GtspInstance::kInfeasibleCost);
  EXPECT_NEAR(r->cost, HeldKarpOptimum(inst), 1e-6);
}

TEST(GtspSolverTest, DeterministicForFixedSeedAndThreads) {
  const GtspInstance inst = RandomInstance(77, 60, 5, kAsymmetric);
  for (int threads : {1, 2}) {
    GtspOptions options;
    options.seed = 42;
    options.num_threads = threads;
    options.effort = GtspEffort::kFast;
    options.max_trials = 4;
    absl::StatusOr<GtspResult> a = SolveGtsp(inst, options);
    absl::StatusOr<GtspResult> b = SolveGtsp(inst, options);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->tour, b->tour) << threads << " threads";
    EXPECT_EQ(a->cost, b->cost);
    EXPECT_EQ(a->iterations, b->iterations);
    EXPECT_EQ(a->trials_completed, 4);
    ExpectValidResult(inst, *a);
  }
}

TEST(GtspSolverTest, ImprovesOnInitialTourAndReportsProgress) {
  const GtspInstance inst = RandomInstance(8, 40, 4, kEuclidean);
  GtspOptions options;
  for (const auto& set : inst.sets) options.initial_tour.push_back(set.back());
  const double initial_cost = TourCost(inst, options.initial_tour);
  std::vector<double> reported;
  options.on_improvement = [&](double cost, double elapsed_s) {
    EXPECT_GE(elapsed_s, 0.0);
    reported.push_back(cost);
  };
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectValidResult(inst, *r);
  EXPECT_LT(r->cost, initial_cost);
  ASSERT_FALSE(reported.empty());
  for (size_t i = 1; i < reported.size(); ++i) EXPECT_LT(reported[i], reported[i - 1]);
  EXPECT_NEAR(reported.back(), r->cost, 1e-6);
  EXPECT_LE(r->time_to_best_s, r->elapsed_s);
}

GtspInstance Tiny() {
  GtspInstance inst;
  inst.num_vertices = 3;
  inst.costs.assign(9, 1.0);
  inst.sets = {{0}, {1, 2}};
  return inst;
}

void ExpectInvalid(const GtspInstance& inst, const std::string& fragment) {
  absl::Status st = inst.Validate();
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument) << st;
  EXPECT_THAT(std::string(st.message()), HasSubstr(fragment));
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, {});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(GtspValidateTest, RejectsMalformedInstances) {
  ASSERT_TRUE(Tiny().Validate().ok());
  GtspInstance inst = Tiny();
  inst.costs.pop_back();
  ExpectInvalid(inst, "expected num_vertices^2");
  inst = Tiny();
  inst.sets = {{0, 1}, {1, 2}};
  ExpectInvalid(inst, "must be disjoint");
  inst = Tiny();
  inst.sets = {{0}, {1}};
  ExpectInvalid(inst, "vertex 2 belongs to no GTSP set");
  inst = Tiny();
  inst.sets = {{0, 1, 2}, {}};
  ExpectInvalid(inst, "set 1 is empty");
  inst = Tiny();
  inst.sets = {{0, 1, 3}};
  ExpectInvalid(inst, "outside [0, 3)");
  inst = Tiny();
  inst.costs[4] = -1.0;
  ExpectInvalid(inst, "cost(1, 1) = -1");
  inst = Tiny();
  inst.costs[5] = std::numeric_limits<double>::quiet_NaN();
  ExpectInvalid(inst, "cost(1, 2)");
  inst = Tiny();
  inst.sets.clear();
  ExpectInvalid(inst, "no sets");
  inst = GtspInstance();
  ExpectInvalid(inst, "at least one vertex");
}

TEST(GtspValidateTest, RejectsBadOptions) {
  GtspOptions options;
  options.num_threads = 0;
  EXPECT_EQ(SolveGtsp(Tiny(), options).status().code(), absl::StatusCode::kInvalidArgument);
  options = GtspOptions();
  options.max_trials = -2;  // -1 is kLocalStepOnly
  EXPECT_EQ(SolveGtsp(Tiny(), options).status().code(), absl::StatusCode::kInvalidArgument);
  options = GtspOptions();
  options.initial_tour = {1, 2};  // both from set 1
  absl::StatusOr<GtspResult> r = SolveGtsp(Tiny(), options);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("initial_tour"));
}

TEST(GtspValidateTest, ValidateTourChecksOneVertexPerSet) {
  const GtspInstance inst = Tiny();
  EXPECT_TRUE(ValidateTour(inst, {0, 2}).ok());
  EXPECT_EQ(ValidateTour(inst, {0}).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ValidateTour(inst, {1, 2}).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ValidateTour(inst, {0, 7}).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_DOUBLE_EQ(TourCost(inst, {0, 2}), 2.0);
}

}  // namespace
}  // namespace covplan
