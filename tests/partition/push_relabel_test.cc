// PushRelabelPartitioner (the cut graph by push-relabel on the grid) against
// brute force, the LP, Boost's Boykov-Kolmogorov and the matching.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/partition/push_relabel_partitioner.h"
#include "tests/testing/grid_fixtures.h"

namespace covplan {
namespace {

using ::covplan::testing::BruteForceMinRanks;
using ::covplan::testing::CheckExactCover;
using ::covplan::testing::RandomGrid;

// An exact cover of `g` by `expected` ranks, or the first thing wrong.
std::string CheckPushRelabel(const Grid& g, int64_t expected) {
  auto p = PushRelabelPartitioner().Partition(g, StopToken());
  if (!p.ok()) return std::string(p.status().ToString());
  if (static_cast<int64_t>(p->ranks.size()) != expected) {
    return std::to_string(p->ranks.size()) + " ranks, expected " + std::to_string(expected);
  }
  if (p->objective != static_cast<double>(expected)) return "objective differs";
  if (CountRankStarts(g, p->orientation) != expected)
    return "rank starts of the orientation differ";
  return CheckExactCover(g, p->ranks);
}

Grid WithRandomWalls(const Grid& base, uint32_t seed, int one_in) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> walls(base.size(), 0);
  for (auto& w : walls) {
    w = static_cast<uint8_t>((rng() % one_in == 0 ? Grid::kWallRight : 0) |
                             (rng() % one_in == 0 ? Grid::kWallUp : 0));
  }
  return Grid(base.rows(), base.cols(), 1.0, {0, 0}, base.free_flags(), walls);
}

TEST(PushRelabelPartitioner, SmallShapes) {
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({"....."}), 1), "");
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({".", ".", ".", "."}), 1), "");
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({"#.#", "...", "#.#"}), 3), "");
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({".###", ".###", "...."}), 2), "");
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({"#.#.", "....", "#.#."}), 4), "");
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({"."}), 1), "");
  EXPECT_EQ(CheckPushRelabel(Grid::FromAscii({".#.", "#.#", ".#."}), 5), "");
  // An open square: one rank per row (or column).
  EXPECT_EQ(CheckPushRelabel(RandomGrid(40, 40, 1.0, 1), 40), "");
}

TEST(PushRelabelPartitioner, RanksNeverCrossBarriers) {
  Grid g = Grid::FromAscii({
      "_.....",
      "..|...",
      "......",
  });
  EXPECT_EQ(CheckPushRelabel(g, BruteForceMinRanks(g)), "");
  Grid column = Grid::FromAscii({".", "_", ".", "."});
  EXPECT_EQ(CheckPushRelabel(column, 2), "");
  auto p = PushRelabelPartitioner().Partition(column, StopToken());
  ASSERT_TRUE(p.ok());
  for (const Rank& r : p->ranks)
    EXPECT_FALSE(r.first.row <= 1 && r.last.row >= 2) << "rank crosses the wall";
}

TEST(PushRelabelPartitioner, MatchesBruteForceOnTinyGrids) {
  for (uint32_t seed = 0; seed < 150; ++seed) {
    Grid g = RandomGrid(1 + seed % 4, 1 + (seed / 4) % 4, 0.75, seed);
    if (g.CountFree() == 0) continue;
    ASSERT_EQ(CheckPushRelabel(g, BruteForceMinRanks(g)), "") << "seed " << seed;
    if (seed % 3 == 0) {
      Grid walled = WithRandomWalls(g, seed, 3);
      ASSERT_EQ(CheckPushRelabel(walled, BruteForceMinRanks(walled)), "") << "walled seed " << seed;
    }
  }
}

TEST(PushRelabelPartitioner, EqualsLpAndBoykovKolmogorovOnRandomGrids) {
  int checked = 0;
  for (uint32_t seed = 0; seed < 200; ++seed) {
    const int rows = 3 + seed % 17, cols = 3 + (seed * 7) % 19;
    Grid g = RandomGrid(rows, cols, 0.55 + 0.4 * ((seed % 10) / 10.0), 1000 + seed);
    if (seed % 2 == 1) g = WithRandomWalls(g, seed, 6);
    if (g.CountFree() == 0) continue;
    auto lp = LpPartitioner().Partition(g, StopToken());
    auto bk = MinCutPartitioner(/*greedy_preflow=*/false).Partition(g, StopToken());
    ASSERT_TRUE(lp.ok() && bk.ok());
    ASSERT_EQ(lp->ranks.size(), bk->ranks.size()) << "seed " << seed;
    ASSERT_EQ(CheckPushRelabel(g, static_cast<int64_t>(lp->ranks.size())), "") << "seed " << seed;
    ++checked;
  }
  EXPECT_GE(checked, 190);
}

// Open fields are what the solver is for: long paths from the few sources
// to the few sinks, many global relabellings, and excess that never reaches
// the sink. Boykov-Kolmogorov and the matching are the references (the LP
// is slow here).
TEST(PushRelabelPartitioner, EqualsBoykovKolmogorovAndMatchingOnOpenFields) {
  for (uint32_t seed = 0; seed < 10; ++seed) {
    Grid g = RandomGrid(80 + 37 * seed, 120 + 23 * seed, 0.97 + 0.003 * seed, 500 + seed);
    if (seed % 2 == 1) g = WithRandomWalls(g, seed, 60);
    auto bk = MinCutPartitioner().Partition(g, StopToken());
    auto matching = MatchingPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(bk.ok() && matching.ok());
    ASSERT_EQ(bk->ranks.size(), matching->ranks.size()) << "seed " << seed;
    ASSERT_EQ(CheckPushRelabel(g, static_cast<int64_t>(bk->ranks.size())), "") << "seed " << seed;
  }
}

// An empty lawn: every source (wide lawns) or every sink (tall ones) is
// served along forward arcs, so the greedy start is a maximum flow and is
// kept; one post breaks that and the greedy flow is undone.
TEST(PushRelabelPartitioner, OpenRectanglesWithAndWithoutAPost) {
  for (const auto& [rows, cols] : std::vector<std::pair<int, int>>{
           {1, 9}, {9, 1}, {2, 2}, {7, 30}, {30, 7}, {64, 64}, {120, 45}}) {
    Grid lawn = RandomGrid(rows, cols, 1.0, 1);
    EXPECT_EQ(CheckPushRelabel(lawn, std::min(rows, cols)), "") << rows << " x " << cols;
    std::vector<uint8_t> free = lawn.free_flags();
    free[static_cast<size_t>(rows / 2) * cols + cols / 2] = 0;
    Grid post(rows, cols, 1.0, {0, 0}, std::move(free));
    if (post.CountFree() == 0) continue;
    auto bk = MinCutPartitioner().Partition(post, StopToken());
    ASSERT_TRUE(bk.ok());
    EXPECT_EQ(CheckPushRelabel(post, static_cast<int64_t>(bk->ranks.size())), "")
        << rows << " x " << cols << " with a post";
  }
}

TEST(PushRelabelPartitioner, StopsWhenCancelledOrPastTheDeadline) {
  Grid g = RandomGrid(50, 50, 0.9, 3);
  StopToken cancelled;
  cancelled.Cancel();
  EXPECT_EQ(PushRelabelPartitioner().Partition(g, cancelled).status().code(),
            absl::StatusCode::kDeadlineExceeded);
  const StopToken late = StopToken::WithDeadline(absl::Now() - absl::Seconds(1));
  EXPECT_EQ(PushRelabelPartitioner().Partition(g, late).status().code(),
            absl::StatusCode::kDeadlineExceeded);
}

TEST(PushRelabelPartitioner, StopsWhenCancelledWhileRunning) {
  // The 10^6 field takes hundreds of milliseconds (seconds under the
  // sanitizers); it is cancelled 50 ms in, wherever it is by then.
  Grid g = RandomGrid(1000, 1000, 0.99, 7);
  StopToken stop;
  std::thread canceller([stop]() mutable {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop.Cancel();
  });
  const absl::StatusCode code = PushRelabelPartitioner().Partition(g, stop).status().code();
  canceller.join();
  EXPECT_EQ(code, absl::StatusCode::kDeadlineExceeded);
}

TEST(PushRelabelPartitioner, StopsOnAShortDeadline) {
  // A 1,000 x 1,000 field with scattered posts takes hundreds of
  // milliseconds; a 1 ms deadline passes during the pushes or a relabelling.
  Grid g = RandomGrid(1000, 1000, 0.99, 5);
  const StopToken soon = StopToken::WithTimeout(absl::Milliseconds(1));
  EXPECT_EQ(PushRelabelPartitioner().Partition(g, soon).status().code(),
            absl::StatusCode::kDeadlineExceeded);
}

TEST(PushRelabelPartitioner, RejectsGridsWithoutFreeCells) {
  auto p = PushRelabelPartitioner().Partition(Grid::FromAscii({"##", "##"}), StopToken());
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(p.status().message(), ::testing::HasSubstr("no free cell"));
  EXPECT_EQ(PushRelabelPartitioner().Partition(Grid(), StopToken()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// The flow audit that runs before every answer catches a damaged flow
// (and passes an undamaged one), so the rank check after it is a proof.
TEST(PushRelabelPartitioner, FlowAuditCatchesADamagedFlow) {
  using push_relabel_internal::AuditDamagedFlow;
  using push_relabel_internal::FlowDamage;
  for (const Grid& g : {RandomGrid(40, 30, 0.92, 7), RandomGrid(25, 60, 0.8, 11)}) {
    EXPECT_TRUE(AuditDamagedFlow(g, FlowDamage::kNone).ok());
    const absl::Status missing = AuditDamagedFlow(g, FlowDamage::kFlowOnMissingArc);
    EXPECT_TRUE(absl::IsInternal(missing)) << missing;
    EXPECT_THAT(missing.message(), ::testing::HasSubstr("flow on a missing arc"));
    for (FlowDamage damage : {FlowDamage::kUnitLost, FlowDamage::kExtraUnitToT}) {
      const absl::Status broken = AuditDamagedFlow(g, damage);
      EXPECT_TRUE(absl::IsInternal(broken)) << broken;
      EXPECT_THAT(broken.message(), ::testing::HasSubstr("flow not conserved"));
    }
  }
}

}  // namespace
}  // namespace covplan
