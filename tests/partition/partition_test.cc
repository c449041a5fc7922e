#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "tests/testing/grid_fixtures.h"

namespace covplan {
namespace {

using ::covplan::testing::BruteForceMinRanks;
using ::covplan::testing::CheckExactCover;
using ::covplan::testing::RandomGrid;

TEST(MinCutPartitioner, SingleRowIsOneHorizontalRank) {
  Grid g = Grid::FromAscii({"....."});
  auto p = MinCutPartitioner().Partition(g, StopToken());
  ASSERT_TRUE(p.ok()) << p.status();
  ASSERT_EQ(p->ranks.size(), 1u);
  EXPECT_EQ(p->ranks[0].orientation, Orientation::kHorizontal);
  EXPECT_EQ(p->ranks[0].NumCells(), 5);
}

TEST(MinCutPartitioner, SingleColumnIsOneVerticalRank) {
  Grid g = Grid::FromAscii({".", ".", ".", "."});
  auto p = MinCutPartitioner().Partition(g, StopToken());
  ASSERT_TRUE(p.ok()) << p.status();
  ASSERT_EQ(p->ranks.size(), 1u);
  EXPECT_EQ(p->ranks[0].orientation, Orientation::kVertical);
}

TEST(MinCutPartitioner, PlusShapeNeedsThreeRanks) {
  // A plus: one long horizontal rank through the middle, the vertical arm is
  // split into two.
  Grid g = Grid::FromAscii({
      "#.#",
      "...",
      "#.#",
  });
  auto p = MinCutPartitioner().Partition(g, StopToken());
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_EQ(p->ranks.size(), 3u);
  EXPECT_EQ(CheckExactCover(g, p->ranks), "");
}

TEST(MinCutPartitioner, LShapeNeedsTwoRanks) {
  Grid g = Grid::FromAscii({
      ".###",
      ".###",
      "....",
  });
  auto p = MinCutPartitioner().Partition(g, StopToken());
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_EQ(p->ranks.size(), 2u);
  EXPECT_EQ(CheckExactCover(g, p->ranks), "");
}

TEST(Partitioners, RanksNeverCrossBarriers) {
  // A thin wall between columns 2 and 3 of the middle row, and below the
  // top-left cell: the row splits into two ranks.
  Grid g = Grid::FromAscii({
      "_.....",
      "..|...",
      "......",
  });
  for (const RankPartitioner* p : {static_cast<const RankPartitioner*>(new MinCutPartitioner()),
                                   static_cast<const RankPartitioner*>(new LpPartitioner())}) {
    auto part = p->Partition(g, StopToken());
    ASSERT_TRUE(part.ok()) << part.status();
    for (const Rank& r : part->ranks) {
      if (r.orientation == Orientation::kHorizontal && r.first.row == 1) {
        EXPECT_FALSE(r.first.col <= 2 && r.last.col >= 3) << "rank crosses the wall";
      }
      if (r.orientation == Orientation::kVertical && r.first.col == 0) {
        EXPECT_FALSE(r.first.row <= 1 && r.last.row >= 2) << "rank crosses the wall";
      }
    }
    EXPECT_EQ(CountRankStarts(g, part->orientation), static_cast<int64_t>(part->ranks.size()));
    EXPECT_EQ(CheckExactCover(g, part->ranks), "");
    delete p;
  }
  // Without walls this grid needs 3 ranks (one per row); the wall in the
  // middle row costs one more, the one under the top-left cell none.
  auto cut = MinCutPartitioner().Partition(g, StopToken());
  EXPECT_EQ(cut->ranks.size(), 4u);
  EXPECT_EQ(BruteForceMinRanks(g), 4);
}

TEST(Partitioners, MinCutEqualsLpWithRandomBarriers) {
  for (uint32_t seed = 0; seed < 100; ++seed) {
    Grid base = RandomGrid(4 + seed % 9, 4 + (seed * 5) % 11, 0.85, 7000 + seed);
    std::mt19937 rng(seed);
    std::vector<uint8_t> walls(base.size());
    for (auto& w : walls)
      w = rng() % 5 == 0 ? Grid::kWallRight : (rng() % 5 == 0 ? Grid::kWallUp : 0);
    Grid g(base.rows(), base.cols(), 1.0, {0, 0}, base.free_flags(), walls);
    if (g.CountFree() == 0) continue;
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    auto lp = LpPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok() && lp.ok());
    ASSERT_EQ(cut->ranks.size(), lp->ranks.size()) << "seed " << seed;
    ASSERT_EQ(CheckExactCover(g, cut->ranks), "");
    if (g.CountFree() <= 14) {
      EXPECT_EQ(static_cast<int64_t>(cut->ranks.size()), BruteForceMinRanks(g)) << "seed " << seed;
    }
  }
}

TEST(MinCutPartitioner, RejectsGridWithoutFreeCells) {
  Grid g = Grid::FromAscii({"##", "##"});
  auto p = MinCutPartitioner().Partition(g, StopToken());
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(p.status().message(), ::testing::HasSubstr("no free cell"));
}

TEST(LpPartitioner, RejectsGridWithoutFreeCells) {
  Grid g = Grid::FromAscii({"#"});
  auto p = LpPartitioner().Partition(g, StopToken());
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(Partitioners, MatchBruteForceOnTinyGrids) {
  for (uint32_t seed = 0; seed < 150; ++seed) {
    const int rows = 1 + seed % 4, cols = 1 + (seed / 4) % 4;
    Grid g = RandomGrid(rows, cols, 0.75, seed);
    if (g.CountFree() == 0) continue;
    const int64_t expected = BruteForceMinRanks(g);
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    auto lp = LpPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok()) << cut.status();
    ASSERT_TRUE(lp.ok()) << lp.status();
    EXPECT_EQ(static_cast<int64_t>(cut->ranks.size()), expected) << "seed " << seed;
    EXPECT_EQ(static_cast<int64_t>(lp->ranks.size()), expected) << "seed " << seed;
  }
}

TEST(Partitioners, MinCutEqualsLpOptimumOnRandomGrids) {
  int checked = 0;
  for (uint32_t seed = 0; seed < 300; ++seed) {
    const int rows = 3 + seed % 17, cols = 3 + (seed * 7) % 19;
    const double free_prob = 0.55 + 0.4 * ((seed % 10) / 10.0);
    Grid g = RandomGrid(rows, cols, free_prob, 1000 + seed);
    if (g.CountFree() == 0) continue;
    auto cut = MinCutPartitioner().Partition(g, StopToken());
    auto lp = LpPartitioner().Partition(g, StopToken());
    ASSERT_TRUE(cut.ok()) << cut.status();
    ASSERT_TRUE(lp.ok()) << lp.status();
    ASSERT_EQ(cut->ranks.size(), lp->ranks.size()) << "seed " << seed;
    EXPECT_DOUBLE_EQ(lp->objective, static_cast<double>(lp->ranks.size()));
    ASSERT_EQ(CheckExactCover(g, cut->ranks), "") << "seed " << seed;
    ASSERT_EQ(CheckExactCover(g, lp->ranks), "") << "seed " << seed;
    EXPECT_EQ(CountRankStarts(g, cut->orientation), static_cast<int64_t>(cut->ranks.size()));
    ++checked;
  }
  EXPECT_GE(checked, 290);
}

TEST(MinCutPartitioner, GreedyPreflowDoesNotChangeTheOptimum) {
  for (uint32_t seed = 0; seed < 60; ++seed) {
    Grid g = RandomGrid(20 + seed % 30, 25 + seed % 17, 0.9 + 0.001 * (seed % 90), 500 + seed);
    auto with = MinCutPartitioner(true).Partition(g, StopToken());
    auto without = MinCutPartitioner(false).Partition(g, StopToken());
    ASSERT_TRUE(with.ok() && without.ok());
    EXPECT_EQ(with->ranks.size(), without->ranks.size()) << "seed " << seed;
    EXPECT_EQ(CheckExactCover(g, with->ranks), "");
  }
}

TEST(Partitioners, RanksAreMaximalRuns) {
  Grid g = RandomGrid(30, 40, 0.8, 77);
  auto cut = MinCutPartitioner().Partition(g, StopToken());
  ASSERT_TRUE(cut.ok());
  // A maximal run cannot be extended by a free cell of the same orientation.
  for (const Rank& r : cut->ranks) {
    const uint8_t o = static_cast<uint8_t>(r.orientation);
    if (r.orientation == Orientation::kHorizontal) {
      for (int c : {r.first.col - 1, r.last.col + 1}) {
        if (g.IsFree(r.first.row, c)) {
          EXPECT_NE(cut->orientation[g.Index(r.first.row, c)], o);
        }
      }
    } else {
      for (int row : {r.first.row - 1, r.last.row + 1}) {
        if (g.IsFree(row, r.first.col)) {
          EXPECT_NE(cut->orientation[g.Index(row, r.first.col)], o);
        }
      }
    }
  }
}

TEST(MinCutPartitioner, StopsWhenCancelled) {
  Grid g = RandomGrid(50, 50, 0.9, 3);
  StopToken stop;
  stop.Cancel();
  auto p = MinCutPartitioner().Partition(g, stop);
  EXPECT_EQ(p.status().code(), absl::StatusCode::kDeadlineExceeded);
}

}  // namespace
}  // namespace covplan
