// Anytime behaviour: deadlines are honoured, cancellation works, and a valid
// tour comes back even when the stop fires before the search starts.
#include <chrono>
#include <thread>

#include "gtest/gtest.h"
#include "planner/tour/gtsp/gtsp.h"
#include "tests/gtsp/gtsp_test_util.h"
#include "tests/testing/timing.h"

namespace covplan {
namespace {

using testing_gtsp::kAsymmetric;
using testing_gtsp::RandomInstance;

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Time allowed past a deadline or a cancellation: a 50 ms deadline on
// 1,000 vertices ends after 90-105 ms on an idle 2-vCPU VM (covplan gtsp,
// every search, before and after issue 31; the greedy start always runs and
// is not interruptible), and CI is a loaded 2-core machine (a 0.1 s margin
// was exceeded there by 24 ms). Without the stop: minutes.
constexpr double kMargin = 0.25 * testing::kTimingSlowdown;

// ~1000 vertices in 200 sets.
const GtspInstance& LargeInstance() {
  static const GtspInstance* inst = new GtspInstance(RandomInstance(11, 200, 5, kAsymmetric, 5));
  return *inst;
}

TEST(GtspDeadlineTest, FiftyMillisecondDeadlineOnThousandVertices) {
  const GtspInstance& inst = LargeInstance();
  ASSERT_EQ(inst.num_vertices, 1000);
  for (GtspEffort effort : {GtspEffort::kFast, GtspEffort::kThorough}) {
    GtspOptions options;
    options.effort = effort;
    const auto t0 = std::chrono::steady_clock::now();
    options.stop = StopToken::WithTimeout(absl::Milliseconds(50));
    absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
    const double wall = SecondsSince(t0);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_LT(wall, 0.050 + kMargin);
    EXPECT_TRUE(r->stopped_early);
    EXPECT_TRUE(ValidateTour(inst, r->tour).ok());
    EXPECT_DOUBLE_EQ(r->cost, TourCost(inst, r->tour));
  }
}

TEST(GtspDeadlineTest, DeadlineWithTwoThreads) {
  const GtspInstance& inst = LargeInstance();
  GtspOptions options;
  options.num_threads = 2;
  options.effort = GtspEffort::kThorough;
  const auto t0 = std::chrono::steady_clock::now();
  options.stop = StopToken::WithTimeout(absl::Milliseconds(80));
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_LT(SecondsSince(t0), 0.080 + kMargin);
  EXPECT_TRUE(r->stopped_early);
  EXPECT_TRUE(ValidateTour(inst, r->tour).ok());
}

TEST(GtspDeadlineTest, AlreadyStoppedStillReturnsGreedyTour) {
  const GtspInstance& inst = LargeInstance();
  GtspOptions options;
  options.stop.Cancel();
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->stopped_early);
  EXPECT_EQ(r->iterations, 0);
  EXPECT_TRUE(ValidateTour(inst, r->tour).ok());
  EXPECT_DOUBLE_EQ(r->cost, TourCost(inst, r->tour));

  // Both modes: LNS trials (default effort) and the memetic search that
  // fills a thorough solve's deadline.
  for (GtspEffort effort : {GtspEffort::kDefault, GtspEffort::kThorough}) {
    GtspOptions expired;
    expired.effort = effort;
    expired.stop = StopToken::WithDeadline(absl::Now() - absl::Seconds(1));
    r = SolveGtsp(inst, expired);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_TRUE(r->stopped_early) << "effort " << static_cast<int>(effort);
    EXPECT_EQ(r->iterations, 0);
    EXPECT_TRUE(ValidateTour(inst, r->tour).ok());
  }
}

TEST(GtspDeadlineTest, CancellationFromAnotherThread) {
  const GtspInstance& inst = LargeInstance();
  GtspOptions options;
  options.effort = GtspEffort::kThorough;
  options.max_trials = 1000;  // would run for minutes
  const StopToken token = options.stop;
  std::thread canceller([token] {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    token.Cancel();
  });
  const auto t0 = std::chrono::steady_clock::now();
  absl::StatusOr<GtspResult> r = SolveGtsp(inst, options);
  const double wall = SecondsSince(t0);
  canceller.join();
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_LT(wall, 0.040 + kMargin);
  EXPECT_TRUE(r->stopped_early);
  EXPECT_TRUE(ValidateTour(inst, r->tour).ok());
}

TEST(GtspDeadlineTest, LongerRunsDoNotGetWorse) {
  const GtspInstance inst = RandomInstance(12, 80, 4, kAsymmetric);
  GtspOptions quick;
  quick.stop.Cancel();
  absl::StatusOr<GtspResult> greedy = SolveGtsp(inst, quick);
  GtspOptions full;
  full.effort = GtspEffort::kFast;
  absl::StatusOr<GtspResult> searched = SolveGtsp(inst, full);
  ASSERT_TRUE(greedy.ok() && searched.ok());
  EXPECT_LE(searched->cost, greedy->cost);
  EXPECT_FALSE(searched->stopped_early);
}

}  // namespace
}  // namespace covplan
