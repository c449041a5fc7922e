// Off-line STC: every sub-cell of every wholly free coarse cell is visited
// exactly once on a closed tour of length 4·N·D; partly free coarse cells are
// covered with the extra moves and double coverage reported exactly; the
// spanning trees are spanning trees; options are validated.
#include <cmath>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/stc/spanning_tree.h"
#include "planner/stc/stc_planner.h"
#include "tests/stc/stc_test_util.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

std::vector<StcOptions> TreeVariants() {
  std::vector<StcOptions> out(3);
  out[1].tree = StcTreeMethod::kPrim;
  out[2].tree = StcTreeMethod::kPrim;
  out[2].sweep_direction = SweepDirection::kVertical;
  return out;
}

// Index of the last coverage waypoint.
size_t LastCoverage(const CoveragePlan& plan) {
  return plan.sweeps.empty() ? 0 : static_cast<size_t>(plan.sweeps.back().waypoint);
}

// The exact statement of the paper's Theorem 2 for our closed tour: when the
// free cells are exactly N wholly free coarse cells (at some offset of the
// coarse grid) that are connected, the tour from a sub-cell back to it makes
// 4N unit moves, so its length is 4·N·D; every sub-cell is entered exactly
// once before the tour closes, and nothing is covered twice.
TEST(OfflineStc, WhollyFreeCoarseCellsAreVisitedOnceOnATourOfLength4ND) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    for (int shift : {0, 1}) {
      const int n = 5 + static_cast<int>(seed * 7 % 60);
      const double d = seed % 2 ? 0.5 : 0.8;
      const Grid grid = testing::RandomCoarseShape(9, 11, n, seed, shift, d);
      const int64_t free = grid.CountFree();
      ASSERT_EQ(free % 4, 0);
      const int64_t coarse = free / 4;
      for (const StcOptions& options : TreeVariants()) {
        SCOPED_TRACE(absl::StrFormat("seed %d shift %d tree %d dir %d", seed, shift,
                                     static_cast<int>(options.tree),
                                     static_cast<int>(options.sweep_direction)));
        absl::StatusOr<CoveragePlan> plan = testing::PlanStcOnGrid(grid, options);
        ASSERT_TRUE(plan.ok()) << plan.status();
        const StcDetail* detail = plan->detail_as<StcDetail>();
        ASSERT_NE(detail, nullptr);
        EXPECT_EQ(detail->offset, (CellIndex{shift, shift}));
        EXPECT_EQ(detail->coarse_cells, coarse);
        EXPECT_EQ(detail->full_coarse_cells, coarse);
        EXPECT_EQ(detail->partial_coarse_cells, 0);
        EXPECT_EQ(detail->tree_edges, coarse - 1);
        EXPECT_EQ(detail->extra_moves, 0);
        EXPECT_EQ(detail->subcells_covered_twice, 0);
        const double length = plan->stats.coverage_length_m + plan->stats.transition_length_m;
        EXPECT_NEAR(length, 4.0 * coarse * d, 1e-9);
        // Closed: back at the start.
        EXPECT_NEAR(plan->path.front().x, plan->path.back().x, 1e-12);
        EXPECT_NEAR(plan->path.front().y, plan->path.back().y, 1e-12);
        const std::vector<int> entries =
            testing::CellEntries(grid, plan->path, LastCoverage(*plan));
        for (int64_t i = 0; i < grid.size(); ++i) {
          ASSERT_EQ(entries[i], grid.free_flags()[i] ? 1 : 0) << "cell " << i;
        }
        // Only the last move (back into the start) is not coverage.
        EXPECT_NEAR(plan->stats.transition_length_m, d, 1e-9);
      }
    }
  }
}

TEST(OfflineStc, TreesSpanTheCoarseCellsAndTheRingVisitsEachSubCellOnce) {
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const Grid grid = testing::RandomConnectedGrid(16, 19, 0.7, seed);
    for (PartialCells partial : {PartialCells::kCover, PartialCells::kDiscard}) {
      const CoarseGrid coarse(grid, grid, {static_cast<int>(seed % 2), 0}, partial);
      const StcRoot root{coarse.CoarseOf(grid.FromIndex(0)), 0};
      for (const StcTree& tree :
           {BuildDfsTree(coarse, root), BuildPrimTree(coarse, root, SweepDirection::kVertical)}) {
        EXPECT_EQ(tree.num_nodes, coarse.num_nodes());
        // A forest: edges = nodes - trees, and every edge is a link STC may use.
        EXPECT_EQ(tree.num_edges, tree.num_nodes - static_cast<int>(tree.roots.size()));
        for (int id = 0; id < coarse.size(); ++id) {
          for (int side = 0; side < 4; ++side) {
            if (tree.HasEdge(id, side)) {
              EXPECT_TRUE(coarse.CanLink(id, side));
            }
          }
        }
        const std::vector<CellIndex> ring = Circumnavigate(coarse, tree);
        ASSERT_EQ(static_cast<int>(ring.size()), 4 * coarse.num_nodes());
        std::vector<int> seen(static_cast<size_t>(coarse.size()) * 4, 0);
        for (const CellIndex& c : ring) ++seen[coarse.CoarseOf(c) * 4 + coarse.PositionOf(c)];
        for (int id = 0; id < coarse.size(); ++id) {
          for (int p = 0; p < 4; ++p) EXPECT_EQ(seen[id * 4 + p], coarse.IsNode(id) ? 1 : 0);
        }
      }
    }
  }
}

// Partly free coarse cells: every free sub-cell is covered; the reported
// extra moves and double coverage match an independent count on the path.
TEST(OfflineStc, PartlyFreeCoarseCellsAreCoveredAndTheRepeatsAreReportedExactly) {
  int64_t total_extra = 0;
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const Grid grid = testing::RandomConnectedGrid(14, 17, 0.72, seed);
    for (const StcOptions& options : TreeVariants()) {
      SCOPED_TRACE(absl::StrFormat("seed %d tree %d", seed, static_cast<int>(options.tree)));
      absl::StatusOr<CoveragePlan> plan = testing::PlanStcOnGrid(grid, options);
      ASSERT_TRUE(plan.ok()) << plan.status();
      const StcDetail* detail = plan->detail_as<StcDetail>();
      const std::vector<int> entries = testing::CellEntries(grid, plan->path, LastCoverage(*plan));
      int64_t twice = 0, moves = 0;
      for (int64_t i = 0; i < grid.size(); ++i) {
        ASSERT_EQ(entries[i] > 0, grid.free_flags()[i] != 0) << "cell " << i;
        twice += entries[i] > 1;
        moves += entries[i];
      }
      moves -= 1;  // the start is not a move
      EXPECT_EQ(detail->subcells_covered_twice, twice);
      EXPECT_EQ(detail->extra_moves, moves - (grid.CountFree() - 1));
      EXPECT_EQ(detail->discarded_cells, 0);
      total_extra += detail->extra_moves;
    }
  }
  EXPECT_GT(total_extra, 0);  // random grids do have partly free coarse cells
}

// Two small cases worked by hand. A 2x3 block: the coarse cell to the right
// holds only its left column, yet the ring still visits the six cells in a
// cycle with no extra move. A 1x3 corridor: covered in two moves, then two
// moves back to the start.
TEST(OfflineStc, HandWorkedPartialCells) {
  StcOptions fixed;
  fixed.search_offset = false;
  absl::StatusOr<CoveragePlan> block =
      testing::PlanStcOnGrid(Grid::FromAscii({"...", "..."}), fixed);
  ASSERT_TRUE(block.ok());
  EXPECT_EQ(block->detail_as<StcDetail>()->partial_coarse_cells, 1);
  EXPECT_EQ(block->detail_as<StcDetail>()->extra_moves, 0);
  EXPECT_DOUBLE_EQ(block->stats.coverage_length_m + block->stats.transition_length_m, 6.0);
  absl::StatusOr<CoveragePlan> corridor = testing::PlanStcOnGrid(Grid::FromAscii({"..."}), fixed);
  ASSERT_TRUE(corridor.ok());
  EXPECT_EQ(corridor->detail_as<StcDetail>()->extra_moves, 0);
  EXPECT_DOUBLE_EQ(corridor->stats.coverage_length_m, 2.0);
  EXPECT_DOUBLE_EQ(corridor->stats.transition_length_m, 2.0);
  // A single cell: one zero-length coverage segment.
  absl::StatusOr<CoveragePlan> one = testing::PlanStcOnGrid(Grid::FromAscii({"#.", "##"}), fixed);
  ASSERT_TRUE(one.ok());
  ASSERT_EQ(one->sweeps.size(), 1u);
  EXPECT_EQ(one->sweeps[0].cells, (std::vector<CellIndex>{{1, 1}}));
}

TEST(OfflineStc, DiscardingPartialCellsIsThePapersApproximation) {
  const Grid grid = testing::RandomConnectedGrid(14, 17, 0.75, 5);
  StcOptions discard;
  discard.partial_cells = PartialCells::kDiscard;
  absl::StatusOr<CoveragePlan> plan = testing::PlanStcOnGrid(grid, discard);
  ASSERT_TRUE(plan.ok());
  const StcDetail* d = plan->detail_as<StcDetail>();
  EXPECT_GT(d->discarded_cells, 0);
  EXPECT_EQ(d->partial_coarse_cells, 0);
  int64_t swept = 0;
  for (const CoverageSweep& s : plan->sweeps) swept += static_cast<int64_t>(s.cells.size());
  EXPECT_EQ(swept + d->discarded_cells, grid.CountFree());
}

TEST(OfflineStc, PrimFollowsTheSweepDirection) {
  // An open 20 x 20 room: lanes along the sweep direction mean far fewer
  // turns across it than a DFS spiral would need, and the turns differ by
  // direction only through the room's symmetry.
  const Grid room(20, 20, 1.0, {0, 0}, std::vector<uint8_t>(400, 1));
  StcOptions h, v;
  h.tree = v.tree = StcTreeMethod::kPrim;
  v.sweep_direction = SweepDirection::kVertical;
  absl::StatusOr<CoveragePlan> ph = testing::PlanStcOnGrid(room, h);
  absl::StatusOr<CoveragePlan> pv = testing::PlanStcOnGrid(room, v);
  ASSERT_TRUE(ph.ok() && pv.ok());
  double along_h = 0, along_v = 0;
  for (size_t i = 1; i < ph->path.size(); ++i)
    along_h += std::abs(ph->path[i].x - ph->path[i - 1].x);
  for (size_t i = 1; i < pv->path.size(); ++i)
    along_v += std::abs(pv->path[i].y - pv->path[i - 1].y);
  // Horizontal lanes: most of the 400 m of driving is along x (and for
  // vertical lanes along y).
  EXPECT_GT(along_h, 0.8 * 400);
  EXPECT_GT(along_v, 0.8 * 400);
}

TEST(StcOptions, BadOptionsAreInvalidArgumentsNamingTheField) {
  StcOptions o;
  o.tree = static_cast<StcTreeMethod>(9);
  EXPECT_EQ(o.Validate().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(o.Validate().message()), HasSubstr("stc.tree"));
  o = StcOptions();
  o.tree = StcTreeMethod::kPrim;
  o.sweep_direction = static_cast<SweepDirection>(5);
  EXPECT_THAT(std::string(o.Validate().message()), HasSubstr("stc.sweep_direction"));
  o = StcOptions();
  o.sweep_direction = SweepDirection::kVertical;  // DFS has no direction
  EXPECT_THAT(std::string(o.Validate().message()), HasSubstr("stc.sweep_direction"));
  o = StcOptions();
  o.partial_cells = static_cast<PartialCells>(3);
  EXPECT_THAT(std::string(o.Validate().message()), HasSubstr("stc.partial_cells"));
  EXPECT_TRUE(StcOptions().Validate().ok());
}

}  // namespace
}  // namespace covplan
