// MatchingPartitioner (König on the H/V conflict graph) against the min-cut,
// the LP and brute force.
#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "tests/testing/grid_fixtures.h"

namespace covplan {
namespace {

using ::covplan::testing::BruteForceMinRanks;
using ::covplan::testing::CheckExactCover;
using ::covplan::testing::RandomGrid;

constexpr MatchingAlgorithm kAlgorithms[] = {MatchingAlgorithm::kMultiSourceBfs,
                                             MatchingAlgorithm::kHopcroftKarp,
                                             MatchingAlgorithm::kPothenFan};

// Every variant (each algorithm, with and without the greedy start) on `g`:
// an exact cover whose rank count is `expected`. Returns "" or the first failure.
std::string CheckAllVariants(const Grid& g, int64_t expected) {
  for (MatchingAlgorithm algorithm : kAlgorithms) {
    for (bool greedy : {true, false}) {
      const std::string variant = "algorithm " + std::to_string(static_cast<int>(algorithm)) +
                                  (greedy ? " greedy" : " no greedy");
      auto p = MatchingPartitioner(algorithm, greedy).Partition(g, StopToken());
      if (!p.ok()) return variant + ": " + std::string(p.status().ToString());
      if (static_cast<int64_t>(p->ranks.size()) != expected) {
        return variant + ": " + std::to_string(p->ranks.size()) + " ranks, expected " +
               std::to_string(expected);
      }
      if (p->objective != static_cast<double>(expected)) return variant + ": objective differs";
      if (CountRankStarts(g, p->orientation) != expected) return variant + ": rank starts differ";
      const std::string cover = CheckExactCover(g, p->ranks);
      if (!cover.empty()) return variant + ": " + cover;
    }
  }
  return "";
}

TEST(MatchingPartitioner, SmallShapes) {
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({"....."}), 1), "");
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({".", ".", ".", "."}), 1), "");
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({"#.#", "...", "#.#"}), 3), "");
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({".###", ".###", "...."}), 2), "");
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({"#.#.", "....", "#.#."}), 4), "");
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({"."}), 1), "");
  EXPECT_EQ(CheckAllVariants(Grid::FromAscii({".#.", "#.#", ".#."}), 5), "");
}

TEST(MatchingPartitioner, RanksNeverCrossBarriers) {
  // A wall between columns 2 and 3 of the middle row, one under the top-left
  // cell, and a vertical wall splitting a column: 4 + 1 ranks.
  Grid g = Grid::FromAscii({
      "_.....",
      "..|...",
      "......",
  });
  EXPECT_EQ(BruteForceMinRanks(g), 4);
  EXPECT_EQ(CheckAllVariants(g, 4), "");
  // Rows top down: the '_' cell is row 2, its wall lies between rows 2 and 1.
  Grid column = Grid::FromAscii({".", "_", ".", "."});
  EXPECT_EQ(CheckAllVariants(column, 2), "");
  auto p = MatchingPartitioner().Partition(column, StopToken());
  ASSERT_TRUE(p.ok());
  for (const Rank& r : p->ranks)
    EXPECT_FALSE(r.first.row <= 1 && r.last.row >= 2) << "rank crosses the wall";
}

TEST(MatchingPartitioner, MatchesBruteForceOnTinyGrids) {
  for (uint32_t seed = 0; seed < 150; ++seed) {
    Grid g = RandomGrid(1 + seed % 4, 1 + (seed / 4) % 4, 0.75, seed);
    if (g.CountFree() == 0) continue;
    ASSERT_EQ(CheckAllVariants(g, BruteForceMinRanks(g)), "") << "seed " << seed;
  }
}

TEST(MatchingPartitioner, EqualsMinCutAndLpOnRandomGrids) {
  int checked = 0;
  for (uint32_t seed = 0; seed < 200; ++seed) {
    const int rows = 3 + seed % 17, cols = 3 + (seed * 7) % 19;
    Grid g = RandomGrid(rows, cols, 0.55 + 0.4 * ((seed % 10) / 10.0), 1000 + seed);
    if (g.CountFree() == 0) continue;
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    auto lp = LpPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok() && lp.ok());
    ASSERT_EQ(cut->ranks.size(), lp->ranks.size()) << "seed " << seed;
    ASSERT_EQ(CheckAllVariants(g, static_cast<int64_t>(lp->ranks.size())), "") << "seed " << seed;
    ++checked;
  }
  EXPECT_GE(checked, 190);
}

TEST(MatchingPartitioner, EqualsMinCutAndLpWithRandomBarriers) {
  for (uint32_t seed = 0; seed < 100; ++seed) {
    Grid base = RandomGrid(4 + seed % 9, 4 + (seed * 5) % 11, 0.85, 7000 + seed);
    std::mt19937 rng(seed);
    std::vector<uint8_t> walls(base.size());
    for (auto& w : walls) {
      w = static_cast<uint8_t>((rng() % 5 == 0 ? Grid::kWallRight : 0) |
                               (rng() % 5 == 0 ? Grid::kWallUp : 0));
    }
    Grid g(base.rows(), base.cols(), 1.0, {0, 0}, base.free_flags(), walls);
    if (g.CountFree() == 0) continue;
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    auto lp = LpPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok() && lp.ok());
    ASSERT_EQ(cut->ranks.size(), lp->ranks.size()) << "seed " << seed;
    ASSERT_EQ(CheckAllVariants(g, static_cast<int64_t>(lp->ranks.size())), "") << "seed " << seed;
  }
}

// Open fields have long augmenting paths and many phases: the case the
// grafting and the rebuild rule are for. Min-cut only (the LP is slow here).
TEST(MatchingPartitioner, EqualsMinCutOnOpenFields) {
  for (uint32_t seed = 0; seed < 12; ++seed) {
    Grid base = RandomGrid(60 + 13 * seed, 90 + 7 * seed, 0.97 + 0.002 * seed, 300 + seed);
    std::mt19937 rng(seed);
    std::vector<uint8_t> walls(base.size(), 0);
    if (seed % 2 == 1) {
      for (auto& w : walls)
        w = rng() % 50 == 0 ? Grid::kWallRight : (rng() % 50 == 0 ? Grid::kWallUp : 0);
    }
    Grid g(base.rows(), base.cols(), 1.0, {0, 0}, base.free_flags(), walls);
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok());
    ASSERT_EQ(CheckAllVariants(g, static_cast<int64_t>(cut->ranks.size())), "") << "seed " << seed;
  }
}

TEST(MatchingPartitioner, StopsWhenCancelledOrPastTheDeadline) {
  Grid g = RandomGrid(50, 50, 0.9, 3);
  StopToken cancelled;
  cancelled.Cancel();
  const StopToken late = StopToken::WithDeadline(absl::Now() - absl::Seconds(1));
  for (MatchingAlgorithm algorithm : kAlgorithms) {
    EXPECT_EQ(MatchingPartitioner(algorithm).Partition(g, cancelled).status().code(),
              absl::StatusCode::kDeadlineExceeded);
    EXPECT_EQ(MatchingPartitioner(algorithm).Partition(g, late).status().code(),
              absl::StatusCode::kDeadlineExceeded);
  }
}

TEST(MatchingPartitioner, StopsOnAShortDeadline) {
  // A 1,000 x 1,000 open field takes far longer than a millisecond (about a
  // second in Release); the deadline passes while the conflict graph is built
  // or during the phases, and either check must end the call.
  Grid g = RandomGrid(1000, 1000, 0.99, 5);
  for (MatchingAlgorithm algorithm : kAlgorithms) {
    const StopToken soon = StopToken::WithTimeout(absl::Milliseconds(1));
    EXPECT_EQ(MatchingPartitioner(algorithm).Partition(g, soon).status().code(),
              absl::StatusCode::kDeadlineExceeded);
  }
}

TEST(MatchingPartitioner, RejectsGridsWithoutFreeCells) {
  auto p = MatchingPartitioner().Partition(Grid::FromAscii({"##", "##"}), StopToken());
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(p.status().message(), ::testing::HasSubstr("no free cell"));
  EXPECT_EQ(MatchingPartitioner().Partition(Grid(), StopToken()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(MatchingPartitioner, IsMadeByTheFactory) {
  EXPECT_EQ(MakePartitioner(PartitionSolver::kMatching)->name(), "matching");
  EXPECT_EQ(MakePartitioner(PartitionSolver::kMinCut)->name(), "mincut");
  EXPECT_EQ(MakePartitioner(PartitionSolver::kLp)->name(), "lp");
  EXPECT_EQ(MakePartitioner(PartitionSolver::kPushRelabel)->name(), "pushrelabel");
}

}  // namespace
}  // namespace covplan
