#include "planner/replan/rank_replan.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "gtest/gtest.h"
#include "planner/partition/mincut_partitioner.h"
#include "tests/testing/grid_fixtures.h"

namespace covplan {
namespace {

using ::covplan::testing::CheckExactCover;
using ::covplan::testing::RandomGrid;
constexpr int64_t kUnlimited = RankReplanInput::kUnlimited;
const auto kIlp1 = RankReplanMethod::kIlp1;
const auto kIlp2 = RankReplanMethod::kIlp2;

// A random grid with thin-wall barriers between free neighbours.
Grid RandomWalledGrid(int rows, int cols, double free_prob, double wall_prob, uint32_t seed) {
  Grid g = RandomGrid(rows, cols, free_prob, seed);
  if (wall_prob <= 0.0) return g;
  std::mt19937 rng(seed ^ 0x9e3779b9u);
  std::bernoulli_distribution wall(wall_prob);
  std::vector<uint8_t> walls(g.size(), 0);
  for (auto& w : walls) w = (wall(rng) ? Grid::kWallRight : 0) | (wall(rng) ? Grid::kWallUp : 0);
  return Grid(rows, cols, 1.0, {0.0, 0.0}, g.free_flags(), std::move(walls));
}

// `g` with every cell for which block(r, c) holds closed.
template <typename F>
Grid Blocked(const Grid& g, F block) {
  std::vector<uint8_t> free = g.free_flags();
  for (int64_t i = 0; i < g.size(); ++i) {
    const CellIndex c = g.FromIndex(i);
    if (block(c.row, c.col)) free[i] = 0;
  }
  return g.WithFreeFlags(std::move(free));
}

std::vector<Rank> MinCutRanks(const Grid& g) {
  absl::StatusOr<RankPartition> p = MinCutPartitioner().Partition(g, StopToken());
  EXPECT_TRUE(p.ok()) << p.status();
  return p.ok() ? p->ranks : std::vector<Rank>{};
}

absl::StatusOr<RankReplanResult> Replan(const Grid& w, const std::vector<Rank>& old, int64_t budget,
                                        RankReplanMethod method) {
  RankReplanInput in;
  in.cells = &w;
  in.old_ranks = old;
  in.budget = budget;
  return RankReplan(in, method, StopToken::WithTimeout(absl::Seconds(60)));
}

using Key = std::tuple<int, int, int, int, int>;
std::set<Key> Keys(const std::vector<Rank>& ranks) {
  std::set<Key> keys;
  for (const Rank& r : ranks) {
    keys.insert(
        {static_cast<int>(r.orientation), r.first.row, r.first.col, r.last.row, r.last.col});
  }
  return keys;
}

// Checks what every successful result must satisfy.
void ExpectConsistent(const Grid& w, const std::vector<Rank>& old, int64_t budget,
                      const RankReplanResult& r) {
  EXPECT_EQ(CheckExactCover(w, r.ranks), "");
  ASSERT_EQ(r.is_new.size(), r.ranks.size());
  EXPECT_EQ(r.num_new, CountNewRanks(r.ranks, old));
  EXPECT_EQ(r.num_new, std::count(r.is_new.begin(), r.is_new.end(), true));
  EXPECT_LE(static_cast<double>(r.num_new), r.new_rank_bound + 1e-9);
  if (budget != kUnlimited) {
    EXPECT_LE(r.num_new, budget);
  }
  EXPECT_NE(r.relaxation_integral, r.used_mip);
}

// Independent reference: enumerate every orientation of W's cells; the best
// (ranks, secondary) with secondary <= budget, where secondary is m_new (ILP-1)
// or the exact α + β/2 of Lemma 4.2 (ILP-2). {-1, -1} when none fits.
std::pair<int64_t, double> BruteForce(const Grid& w, const std::vector<Rank>& old, int64_t budget,
                                      RankReplanMethod method) {
  std::vector<int64_t> cells;
  for (int64_t i = 0; i < w.size(); ++i) {
    if (w.free_flags()[i]) cells.push_back(i);
  }
  // Old end slots per cell: L, R, B, T.
  std::vector<std::array<int, 4>> old_end(w.size(), {0, 0, 0, 0});
  for (const Rank& r : old) {
    const int h = r.orientation == Orientation::kHorizontal ? 0 : 2;
    old_end[w.Index(r.first.row, r.first.col)][h] = 1;
    old_end[w.Index(r.last.row, r.last.col)][h + 1] = 1;
  }
  std::pair<int64_t, double> best{-1, -1.0};
  std::vector<uint8_t> orient(w.size(), 0);
  for (uint32_t mask = 0; mask < (1u << cells.size()); ++mask) {
    for (size_t k = 0; k < cells.size(); ++k) orient[cells[k]] = (mask >> k) & 1;
    const std::vector<Rank> ranks = RanksFromOrientation(w, orient);
    double secondary = static_cast<double>(CountNewRanks(ranks, old));
    if (method == kIlp2) {
      std::vector<std::array<int, 4>> end(w.size(), {0, 0, 0, 0});
      for (const Rank& r : ranks) {
        const int h = r.orientation == Orientation::kHorizontal ? 0 : 2;
        end[w.Index(r.first.row, r.first.col)][h] = 1;
        end[w.Index(r.last.row, r.last.col)][h + 1] = 1;
      }
      int alpha = 0, beta = 0;
      for (int64_t i : cells) {
        for (int s = 0; s < 4; ++s) {
          alpha += end[i][s] && !old_end[i][s];
          beta += old_end[i][s] && !end[i][s] && orient[i] == (s >= 2 ? 1 : 0);
        }
      }
      secondary = alpha + beta / 2.0;
    }
    if (budget != kUnlimited && secondary > budget) continue;
    const std::pair<int64_t, double> cand{static_cast<int64_t>(ranks.size()), secondary};
    if (best.first < 0 || cand < best) best = cand;
  }
  return best;
}

TEST(RankReplan, Ilp1UnlimitedMatchesMinCutOnRandomGrids) {
  int mip = 0;
  for (uint32_t seed = 1; seed <= 120; ++seed) {
    std::mt19937 rng(seed);
    const int rows = 2 + rng() % 14, cols = 2 + rng() % 19;
    const Grid g =
        RandomWalledGrid(rows, cols, 0.6 + 0.35 * (rng() % 8) / 7.0, seed % 2 ? 0.15 : 0.0, seed);
    const std::vector<Rank> old = MinCutRanks(g);
    std::bernoulli_distribution hit(0.08);
    const Grid w = Blocked(g, [&](int, int) { return hit(rng); });
    if (w.CountFree() == 0) continue;
    SCOPED_TRACE(::testing::Message() << "seed " << seed << " " << rows << "x" << cols);
    absl::StatusOr<RankReplanResult> r = Replan(w, old, kUnlimited, kIlp1);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_EQ(r->ranks.size(), MinCutRanks(w).size());
    ExpectConsistent(w, old, kUnlimited, *r);
    mip += r->used_mip;
  }
  std::printf("ILP-1 unlimited: %d of 120 relaxations needed branch and bound\n", mip);
}

TEST(RankReplan, Ilp1MatchesMinCutOnAsciiMaps) {
  const std::vector<std::vector<std::string>> maps = {
      {"#.#", "...", "#.#"},
      {".###", ".###", "...."},
      {"......", "..|...", "._....", "......"},
      {"..........", ".####.###.", ".#..|...#.", ".#..#_..#.", "....#....."},
      {"...#...", "...#...", "._.....", "...#...", "...#..."},
  };
  for (size_t k = 0; k < maps.size(); ++k) {
    const Grid g = Grid::FromAscii(maps[k]);
    for (RankReplanMethod method : {kIlp1, kIlp2}) {
      absl::StatusOr<RankReplanResult> r = Replan(g, {}, kUnlimited, method);
      ASSERT_TRUE(r.ok()) << "map " << k << ": " << r.status();
      EXPECT_EQ(r->ranks.size(), MinCutRanks(g).size()) << "map " << k;
      ExpectConsistent(g, {}, kUnlimited, *r);
    }
  }
}

TEST(RankReplan, BudgetZeroKeepsExactlyTheOldRanksLyingInW) {
  for (uint32_t seed = 1; seed <= 25; ++seed) {
    const Grid g = RandomWalledGrid(8 + seed % 5, 10 + seed % 7, 0.85, seed % 2 ? 0.1 : 0.0, seed);
    const std::vector<Rank> old = MinCutRanks(g);
    // Remove every third old rank entirely (as if it had been covered).
    std::vector<uint8_t> gone(g.size(), 0);
    std::vector<Rank> kept;
    for (size_t k = 0; k < old.size(); ++k) {
      if (k % 3 != 0) {
        kept.push_back(old[k]);
        continue;
      }
      const Rank& r = old[k];
      for (int i = 0; i < r.NumCells(); ++i) {
        const bool h = r.orientation == Orientation::kHorizontal;
        gone[g.Index(h ? r.first.row : r.first.row + i, h ? r.first.col + i : r.first.col)] = 1;
      }
    }
    const Grid w = Blocked(g, [&](int row, int col) { return gone[g.Index(row, col)] != 0; });
    for (RankReplanMethod method : {kIlp1, kIlp2}) {
      absl::StatusOr<RankReplanResult> r = Replan(w, old, 0, method);
      ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.status();
      EXPECT_EQ(Keys(r->ranks), Keys(kept)) << "seed " << seed;
      EXPECT_EQ(r->num_new, 0);
    }
  }
}

TEST(RankReplan, BudgetZeroFailsWhenAnOldRankIsCut) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const Grid g = RandomWalledGrid(8, 12, 0.9, 0.0, seed);
    const std::vector<Rank> old = MinCutRanks(g);
    auto longest = std::max_element(old.begin(), old.end(), [](const Rank& a, const Rank& b) {
      return a.NumCells() < b.NumCells();
    });
    ASSERT_GE(longest->NumCells(), 3);
    const bool h = longest->orientation == Orientation::kHorizontal;
    const int mid = longest->NumCells() / 2;
    const CellIndex cut{h ? longest->first.row : longest->first.row + mid,
                        h ? longest->first.col + mid : longest->first.col};
    const Grid w = Blocked(g, [&](int row, int col) { return CellIndex{row, col} == cut; });
    for (RankReplanMethod method : {kIlp1, kIlp2}) {
      EXPECT_TRUE(absl::IsFailedPrecondition(Replan(w, old, 0, method).status())) << seed;
      // The two pieces of the cut rank, kept as new ranks, fit a budget of 2.
      absl::StatusOr<RankReplanResult> r = Replan(w, old, 2, method);
      ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.status();
      ExpectConsistent(w, old, 2, *r);
    }
  }
}

TEST(RankReplan, EndpointsOfKeptRanksCannotLeaveAGap) {
  // Old ranks [0..1] and [4..5]; cells 2 and 3 belonged to cut vertical ranks.
  // With y only bounded below (the thesis' ILP-0), phantom ends at 1 and 4 would
  // "keep" both old ranks at zero cost and leave cells 2, 3 uncovered.
  const Grid w = Grid::FromAscii({"......"});
  const std::vector<Rank> old = {{Orientation::kHorizontal, {0, 0}, {0, 1}},
                                 {Orientation::kHorizontal, {0, 4}, {0, 5}}};
  for (RankReplanMethod method : {kIlp1, kIlp2}) {
    EXPECT_TRUE(absl::IsFailedPrecondition(Replan(w, old, 0, method).status()));
    absl::StatusOr<RankReplanResult> r = Replan(w, old, 1, method);
    ASSERT_TRUE(r.ok()) << r.status();
    ASSERT_EQ(r->ranks.size(), 1u);  // the merged rank [0..5]
    EXPECT_EQ(r->num_new, 1);
    ExpectConsistent(w, old, 1, *r);
  }
}

TEST(RankReplan, SplitsALineToKeepTwoTouchingOldRanks) {
  const Grid w = Grid::FromAscii({"......"});
  const std::vector<Rank> old = {{Orientation::kHorizontal, {0, 0}, {0, 2}},
                                 {Orientation::kHorizontal, {0, 3}, {0, 5}}};
  for (RankReplanMethod method : {kIlp1, kIlp2}) {
    absl::StatusOr<RankReplanResult> kept = Replan(w, old, 0, method);
    ASSERT_TRUE(kept.ok()) << kept.status();
    EXPECT_EQ(Keys(kept->ranks), Keys(old));
    absl::StatusOr<RankReplanResult> merged = Replan(w, old, kUnlimited, method);
    ASSERT_TRUE(merged.ok()) << merged.status();
    EXPECT_EQ(merged->ranks.size(), 1u);
    EXPECT_EQ(merged->num_new, 1);
  }
}

TEST(RankReplan, BranchAndBoundWhenTheRelaxationIsFractional) {
  // Tight budgets on heavily blocked W: a few relaxations are fractional.
  int mip = 0;
  for (uint32_t seed = 1; seed <= 60; ++seed) {
    std::mt19937 rng(seed);
    const Grid g = RandomWalledGrid(5 + rng() % 8, 6 + rng() % 10, 0.9, seed % 2 ? 0.1 : 0.0, seed);
    const std::vector<Rank> old = MinCutRanks(g);
    std::bernoulli_distribution hit(0.2);
    const Grid w = Blocked(g, [&](int, int) { return hit(rng); });
    if (w.CountFree() == 0) continue;
    for (int64_t budget : {2, 4, 6, 8, 12}) {
      size_t ilp1_ranks = SIZE_MAX;
      for (RankReplanMethod method : {kIlp1, kIlp2}) {
        absl::StatusOr<RankReplanResult> r = Replan(w, old, budget, method);
        if (absl::IsFailedPrecondition(r.status())) continue;
        ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.status();
        ExpectConsistent(w, old, budget, *r);
        EXPECT_GE(r->ranks.size(), MinCutRanks(w).size());
        if (method == kIlp1) ilp1_ranks = r->ranks.size();
        EXPECT_LE(ilp1_ranks, r->ranks.size()) << "seed " << seed << " budget " << budget;
        mip += r->used_mip;
      }
    }
  }
  std::printf("fractional relaxations solved by branch and bound: %d\n", mip);
  EXPECT_GT(mip, 0) << "no fractional relaxation met: the branch-and-bound path went untested";
}

TEST(RankReplan, MatchesBruteForceOnTinyGrids) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    std::mt19937 rng(seed);
    const Grid g = RandomWalledGrid(3 + seed % 2, 4, 0.9, seed % 3 == 0 ? 0.2 : 0.0, seed);
    const std::vector<Rank> old = MinCutRanks(g);
    std::uniform_int_distribution<int64_t> cell(0, g.size() - 1);
    const int64_t a = cell(rng), b = cell(rng);
    const Grid w = Blocked(
        g, [&](int row, int col) { return g.Index(row, col) == a || g.Index(row, col) == b; });
    if (w.CountFree() == 0 || w.CountFree() > 14) continue;
    for (RankReplanMethod method : {kIlp1, kIlp2}) {
      for (int64_t budget : {int64_t{0}, int64_t{1}, int64_t{2}, int64_t{3}, kUnlimited}) {
        SCOPED_TRACE(::testing::Message() << "seed " << seed << " ILP-" << (method == kIlp1 ? 1 : 2)
                                          << " budget " << budget);
        const auto [best_m, best_s] = BruteForce(w, old, budget, method);
        absl::StatusOr<RankReplanResult> r = Replan(w, old, budget, method);
        if (best_m < 0) {
          EXPECT_TRUE(absl::IsFailedPrecondition(r.status())) << r.status();
          continue;
        }
        ASSERT_TRUE(r.ok()) << r.status();
        EXPECT_EQ(static_cast<int64_t>(r->ranks.size()), best_m);
        EXPECT_NEAR(r->new_rank_bound, best_s, 1e-6);  // fewest new ranks among the minimal
        ExpectConsistent(w, old, budget, *r);
      }
    }
  }
}

TEST(RankReplan, Ilp2NeverExceedsItsBudgetAndIlp1IsNeverWorse) {
  const std::vector<int64_t> budgets = {0, 1, 2, 5, kUnlimited};
  int solved = 0, mip = 0;
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    std::mt19937 rng(seed);
    const int rows = 6 + rng() % 10, cols = 8 + rng() % 13;
    const Grid g = RandomWalledGrid(rows, cols, 0.85, seed % 2 ? 0.1 : 0.0, seed);
    const std::vector<Rank> old = MinCutRanks(g);
    std::bernoulli_distribution hit(0.05);
    const Grid w = Blocked(g, [&](int, int) { return hit(rng); });
    const size_t min_ranks = MinCutRanks(w).size();
    int64_t prev_ilp1 = INT64_MAX;
    for (int64_t budget : budgets) {
      SCOPED_TRACE(::testing::Message() << "seed " << seed << " budget " << budget);
      absl::StatusOr<RankReplanResult> r1 = Replan(w, old, budget, kIlp1);
      absl::StatusOr<RankReplanResult> r2 = Replan(w, old, budget, kIlp2);
      for (const auto* r : {&r1, &r2}) {
        if (r->ok()) ++solved, mip += (*r)->used_mip;
      }
      if (r2.ok()) {
        ExpectConsistent(w, old, budget, *r2);
        ASSERT_TRUE(r1.ok()) << "ILP-2 found a plan ILP-1 missed: " << r1.status();
        EXPECT_LE(r1->ranks.size(), r2->ranks.size());
      } else {
        EXPECT_TRUE(absl::IsFailedPrecondition(r2.status())) << r2.status();
      }
      if (!r1.ok()) {
        EXPECT_TRUE(absl::IsFailedPrecondition(r1.status())) << r1.status();
        continue;
      }
      ExpectConsistent(w, old, budget, *r1);
      EXPECT_LE(static_cast<int64_t>(r1->ranks.size()), prev_ilp1);  // more budget never hurts
      prev_ilp1 = r1->ranks.size();
      if (budget == kUnlimited) {
        EXPECT_EQ(r1->ranks.size(), min_ranks);
        ASSERT_TRUE(r2.ok());
        EXPECT_EQ(r2->ranks.size(), min_ranks);
      }
    }
  }
  std::printf("budgeted ILP-1/ILP-2: %d of %d solved programs needed branch and bound\n", mip,
              solved);
}

TEST(RankReplan, AmongMinimalPartitionsKeepsTheOldRanks) {
  // A 4x4 block without its top-left corner needs 4 ranks either way: four
  // rows (no old rank kept) or four columns (three old vertical ranks kept).
  const Grid full = Grid::FromAscii({"....", "....", "....", "...."});
  const Grid w = Grid::FromAscii({"#...", "....", "....", "...."});
  for (Orientation o : {Orientation::kVertical, Orientation::kHorizontal}) {
    std::vector<Rank> old;
    for (int k = 0; k < 4; ++k) {
      old.push_back(o == Orientation::kVertical ? Rank{o, {0, k}, {3, k}}
                                                : Rank{o, {k, 0}, {k, 3}});
    }
    for (RankReplanMethod method : {kIlp1, kIlp2}) {
      absl::StatusOr<RankReplanResult> kept = Replan(full, old, kUnlimited, method);
      ASSERT_TRUE(kept.ok()) << kept.status();
      EXPECT_EQ(Keys(kept->ranks), Keys(old));  // 4 ranks, all old
      absl::StatusOr<RankReplanResult> r = Replan(w, old, kUnlimited, method);
      ASSERT_TRUE(r.ok()) << r.status();
      EXPECT_EQ(r->ranks.size(), 4u);
      EXPECT_EQ(r->num_new, 1);  // three old ranks kept, one shortened
      for (const Rank& rank : r->ranks) EXPECT_EQ(rank.orientation, o);
    }
  }
}

TEST(RankReplan, BadInputIsInvalidArgument) {
  const Grid g = Grid::FromAscii({"...", "..."});
  const Grid empty = Grid::FromAscii({"##", "##"});
  RankReplanInput in;
  EXPECT_TRUE(absl::IsInvalidArgument(RankReplan(in, kIlp1, StopToken()).status()));
  in.cells = &empty;
  EXPECT_TRUE(absl::IsInvalidArgument(RankReplan(in, kIlp1, StopToken()).status()));
  in.cells = &g;
  in.budget = -2;
  EXPECT_TRUE(absl::IsInvalidArgument(RankReplan(in, kIlp2, StopToken()).status()));
  in.budget = 3;
  const Rank h{Orientation::kHorizontal, {0, 0}, {0, 2}};
  for (const std::vector<Rank>& old : std::vector<std::vector<Rank>>{
           {h, {Orientation::kVertical, {0, 1}, {1, 1}}},  // overlap
           {{Orientation::kHorizontal, {0, 1}, {0, 3}}},   // leaves the grid
           {{Orientation::kHorizontal, {0, 2}, {0, 0}}},   // first > last
           {{Orientation::kVertical, {0, 0}, {1, 1}}}}) {  // not straight
    in.old_ranks = old;
    EXPECT_TRUE(absl::IsInvalidArgument(RankReplan(in, kIlp1, StopToken()).status()));
  }
  in.old_ranks = {h};
  absl::StatusOr<RankReplanResult> ok = RankReplan(in, kIlp1, StopToken());
  ASSERT_TRUE(ok.ok()) << ok.status();
  EXPECT_EQ(ok->ranks.size(), 2u);
}

// An office-like 40x50 floor: rooms split by walls with doors, desks. Not an
// assertion on time: prints how long each method takes.
Grid OfficeGrid(uint32_t seed) {
  std::mt19937 rng(seed);
  return Blocked(Grid(40, 50, 1.0, {0.0, 0.0}, std::vector<uint8_t>(2000, 1)), [&](int r, int c) {
    const bool wall = (r == 13 || r == 27 || c == 12 || c == 25 || c == 38);
    const bool door = (r % 13 >= 5 && r % 13 <= 6) || (c % 12 >= 5 && c % 12 <= 6);
    const bool desk = (r % 6 == 2 && c % 8 >= 2 && c % 8 <= 4) || rng() % 100 < 3;
    return (wall && !door) || desk;
  });
}

TEST(RankReplan, ExpiredOrCancelledTokenStopsBeforeSolving) {
  const Grid g = Grid::FromAscii({"....", "...."});
  RankReplanInput in;
  in.cells = &g;
  const StopToken expired = StopToken::WithDeadline(absl::Now() - absl::Seconds(1));
  EXPECT_TRUE(absl::IsDeadlineExceeded(RankReplan(in, kIlp1, expired).status()));
  EXPECT_TRUE(absl::IsDeadlineExceeded(RankReplan(in, kIlp2, expired).status()));
  const StopToken cancelled;
  cancelled.Cancel();
  EXPECT_TRUE(absl::IsCancelled(RankReplan(in, kIlp2, cancelled).status()));
  // GLPK gets the remaining time as its limit.
  const Grid office = OfficeGrid(7);
  in.cells = &office;
  const absl::Time start = absl::Now();
  EXPECT_TRUE(absl::IsDeadlineExceeded(
      RankReplan(in, kIlp1, StopToken::WithTimeout(absl::Milliseconds(30))).status()));
  EXPECT_LT(absl::Now() - start, absl::Seconds(2));
}

TEST(RankReplan, TimingOnOfficeGrid) {
  const Grid office = OfficeGrid(7);
  const std::vector<Rank> old = MinCutRanks(office);
  for (int num_obstacles : {1, 6}) {
    std::mt19937 rng(11);
    std::vector<CellIndex> obstacles;  // 2x2 boxes
    for (int k = 0; k < num_obstacles; ++k) {
      obstacles.push_back({static_cast<int>(rng() % 38), static_cast<int>(rng() % 48)});
    }
    const Grid w = Blocked(office, [&](int r, int c) {
      for (CellIndex o : obstacles) {
        if (r >= o.row && r < o.row + 2 && c >= o.col && c < o.col + 2) return true;
      }
      return false;
    });
    std::printf("office, %d obstacles: %lld free cells, %zu old ranks, min-cut on W %zu ranks\n",
                num_obstacles, static_cast<long long>(w.CountFree()), old.size(),
                MinCutRanks(w).size());
    for (RankReplanMethod method : {kIlp1, kIlp2}) {
      for (int64_t budget : {int64_t{5}, kUnlimited}) {
        const absl::Time start = absl::Now();
        absl::StatusOr<RankReplanResult> r = Replan(w, old, budget, method);
        std::printf("  ILP-%d budget %2lld: %7.1f ms: ", method == kIlp1 ? 1 : 2,
                    static_cast<long long>(budget),
                    absl::ToDoubleMilliseconds(absl::Now() - start));
        if (!r.ok()) {
          std::printf("%s\n", std::string(r.status().message()).c_str());
          EXPECT_TRUE(absl::IsFailedPrecondition(r.status())) << r.status();
          continue;
        }
        std::printf("%zu ranks, %lld new, %lld cols, %lld rows, build %.1f ms, solve %.1f ms, %s\n",
                    r->ranks.size(), static_cast<long long>(r->num_new),
                    static_cast<long long>(r->num_columns), static_cast<long long>(r->num_rows),
                    r->build_ms, r->solve_ms, r->used_mip ? "branch and bound" : "integral LP");
        ExpectConsistent(w, old, budget, *r);
      }
    }
  }
}

// The estimate against a count of its own: 6 per free cell, and n (n + 1) / 2
// for every maximal run of n linked free cells, walked cell by cell through
// LeftLinked / BelowLinked.
TEST(Ilp1ColumnEstimate, CountsCellsAndPairsOfEveryRun) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const Grid w = RandomWalledGrid(9, 13, 0.8, 0.15, seed);
    int64_t expected = 6 * w.CountFree();
    for (const bool horizontal : {true, false}) {
      for (int outer = 0; outer < (horizontal ? w.rows() : w.cols()); ++outer) {
        int64_t run = 0;
        for (int inner = 0; inner < (horizontal ? w.cols() : w.rows()); ++inner) {
          const int r = horizontal ? outer : inner, c = horizontal ? inner : outer;
          const bool linked = horizontal ? w.LeftLinked(r, c) : w.BelowLinked(r, c);
          if (!w.IsFree(r, c) || !linked) expected += run * (run + 1) / 2, run = 0;
          if (w.IsFree(r, c)) ++run;
        }
        expected += run * (run + 1) / 2;
      }
    }
    EXPECT_EQ(Ilp1ColumnEstimate(w), expected) << "seed " << seed;
  }
  // One row of three free cells: 18 + 6 (the row) + 3 (three vertical runs of one).
  const Grid row(1, 3, 1.0, {0.0, 0.0}, std::vector<uint8_t>{1, 1, 1});
  EXPECT_EQ(Ilp1ColumnEstimate(row), 27);
}

}  // namespace
}  // namespace covplan
