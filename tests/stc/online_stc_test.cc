// On-line and ant-like STC on a simulated robot cover the same sub-cells as
// off-line STC on the same map (and, where every coarse cell is wholly free,
// drive exactly the off-line path).
#include <optional>
#include <set>
#include <tuple>
#include <vector>

#include "gtest/gtest.h"
#include "planner/stc/online_stc.h"
#include "planner/stc/spanning_tree.h"
#include "planner/stc/stc_planner.h"
#include "tests/stc/stc_test_util.h"

namespace covplan {
namespace {

using CellSet = std::set<std::pair<int, int>>;

CellSet SetOf(const std::vector<CellIndex>& cells) {
  CellSet s;
  for (const CellIndex& c : cells) s.insert({c.row, c.col});
  return s;
}

// Off-line STC as the robots run it: DFS, coarse grid at offset 0.
StcOptions OfflineLikeOnline(PartialCells partial) {
  StcOptions o;
  o.search_offset = false;
  o.partial_cells = partial;
  return o;
}

// The cells the off-line walk stands in: the start, then every step.
std::vector<CellIndex> OfflineTrail(const Grid& grid, const StcOptions& options, CellIndex start,
                                    StcDetail* detail = nullptr) {
  absl::StatusOr<StcOutcome> out = RunOfflineStc(grid, grid, options, start, start, StopToken());
  EXPECT_TRUE(out.ok()) << out.status();
  if (!out.ok()) return {};
  if (detail != nullptr) *detail = *out->detail;
  std::vector<CellIndex> trail = {start};
  trail.insert(trail.end(), out->walk.steps.begin(), out->walk.steps.end());
  return trail;
}

TEST(OnlineStc, CoversTheSameSubCellsAsOfflineIncludingPartlyFreeCoarseCells) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE(seed);
    const Grid truth = testing::RandomConnectedGrid(15, 18, 0.72, seed);
    // The first free cell of a tree node (the robots start inside the tree).
    const CoarseGrid coarse(truth, truth, {0, 0}, PartialCells::kCover);
    std::optional<CellIndex> start;
    for (int64_t i = 0; i < truth.size() && !start; ++i) {
      if (truth.free_flags()[i] && !coarse.IsOrphan(truth.FromIndex(i))) start = truth.FromIndex(i);
    }
    ASSERT_TRUE(start.has_value());
    StcDetail detail;
    const std::vector<CellIndex> offline =
        OfflineTrail(truth, OfflineLikeOnline(PartialCells::kCover), *start, &detail);
    SubCellRobot robot(truth, *start);
    absl::StatusOr<OnlineStcStats> online = RunOnlineStc(&robot, PartialCells::kCover);
    ASSERT_TRUE(online.ok()) << online.status();
    EXPECT_EQ(SetOf(robot.trail()), SetOf(offline));
    EXPECT_EQ(static_cast<int64_t>(SetOf(robot.trail()).size()), truth.CountFree());
    EXPECT_EQ(robot.trail().back(), *start);  // closed tour
    // The on-line tree is the off-line DFS tree of the start's component.
    EXPECT_LE(online->tree_edges, detail.tree_edges);
    if (detail.trees == 1) {
      EXPECT_EQ(online->tree_edges, detail.tree_edges);
    }
  }
}

TEST(OnlineStc, BothRobotsDriveTheOfflinePathWhenEveryCoarseCellIsWhollyFree) {
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    SCOPED_TRACE(seed);
    const Grid truth = testing::RandomCoarseShape(8, 9, 10 + static_cast<int>(seed), seed);
    absl::StatusOr<CellIndex> first = DefaultStartCell(truth, truth);
    ASSERT_TRUE(first.ok());
    // Start in different sub-cells of the first coarse cell.
    const CellIndex start{first->row + static_cast<int>(seed % 2),
                          first->col + static_cast<int>(seed / 2 % 2)};
    const std::vector<CellIndex> offline =
        OfflineTrail(truth, OfflineLikeOnline(PartialCells::kCover), start);
    ASSERT_EQ(static_cast<int64_t>(offline.size()), truth.CountFree() + 1);
    SubCellRobot online_robot(truth, start);
    ASSERT_TRUE(RunOnlineStc(&online_robot, PartialCells::kCover).ok());
    EXPECT_EQ(online_robot.trail(), offline);
    SubCellRobot ant(truth, start);
    absl::StatusOr<OnlineStcStats> stats = RunAntStc(&ant);
    ASSERT_TRUE(stats.ok()) << stats.status();
    EXPECT_EQ(ant.trail(), offline);
    EXPECT_EQ(stats->max_stored_cells, 0);
    for (int64_t i = 0; i < truth.size(); ++i) {
      if (truth.free_flags()[i]) {
        EXPECT_TRUE(ant.Marked(truth.FromIndex(i)));
      }
    }
  }
}

// The paper's model, partly free coarse cells discarded: ant-like and
// on-line STC cover the sub-cells of the off-line tree grown from the start.
TEST(AntStc, CoversTheSameSubCellsAsOfflineWithPartialCellsDiscarded) {
  int compared = 0;
  for (uint32_t seed = 1; seed <= 60; ++seed) {
    SCOPED_TRACE(seed);
    const Grid truth = testing::RandomConnectedGrid(16, 16, 0.85, seed);
    const CoarseGrid coarse(truth, truth, {0, 0}, PartialCells::kDiscard);
    int start_cell = -1;
    for (int id = 0; id < coarse.size() && start_cell < 0; ++id) {
      if (coarse.IsNode(id)) start_cell = id;
    }
    if (start_cell < 0) continue;
    const CellIndex start = coarse.SubCell(start_cell, 2);
    const StcTree tree = BuildDfsTree(coarse, {start_cell, 2});
    // The off-line ring of the start's tree.
    std::vector<CellIndex> ring;
    StcRoot at = tree.roots[0];
    do {
      ring.push_back(coarse.SubCell(at.cell, at.position));
      at = NextOnRing(coarse, tree, at);
    } while (at.cell != tree.roots[0].cell || at.position != tree.roots[0].position);
    SubCellRobot ant(truth, start);
    ASSERT_TRUE(RunAntStc(&ant).ok());
    EXPECT_EQ(SetOf(ant.trail()), SetOf(ring));
    ring.push_back(start);
    EXPECT_EQ(ant.trail(), ring);  // wholly free cells only: the ring itself, closed
    SubCellRobot online(truth, start);
    ASSERT_TRUE(RunOnlineStc(&online, PartialCells::kDiscard).ok());
    EXPECT_EQ(online.trail(), ring);
    ++compared;
  }
  EXPECT_GT(compared, 40);
}

TEST(SubCellRobot, RefusesMovesTheTruthBlocks) {
  const Grid truth = Grid::FromAscii({"..#", ".|."});
  SubCellRobot robot(truth, {0, 1});
  EXPECT_EQ(robot.Step({0, 2}).code(), absl::StatusCode::kFailedPrecondition);  // thin wall
  EXPECT_EQ(robot.Step({1, 1}).code(), absl::StatusCode::kOk);
  EXPECT_EQ(robot.Step({1, 2}).code(), absl::StatusCode::kFailedPrecondition);  // obstacle
  EXPECT_EQ(robot.Step({0, 0}).code(), absl::StatusCode::kFailedPrecondition);  // not a neighbour
  SubCellRobot ant(truth, {0, 2});
  EXPECT_EQ(RunAntStc(&ant).status().code(),
            absl::StatusCode::kInvalidArgument);  // partly free start cell
}

}  // namespace
}  // namespace covplan
