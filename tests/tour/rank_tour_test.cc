#include "planner/tour/rank_tour.h"

#include <cmath>

#include "gtest/gtest.h"
#include "planner/engine/engine.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/tour/grid_paths.h"
#include "tests/testing/grid_fixtures.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

struct Fixture {
  Grid grid;
  RankPartition partition;
  std::shared_ptr<const TransitionTable> table;
};

Fixture Make(Grid grid) {
  Fixture f{std::move(grid), {}, nullptr};
  f.partition = *MinCutPartitioner().Partition(f.grid, StopToken());
  f.table = *TransitionTable::Build(f.grid, f.partition.ranks, StopToken(), 2);
  return f;
}

CoveragePlan AsPlan(const Fixture& f, const RankTourCost& cost, const TourOrder& tour,
                    const RobotModel& robot) {
  CoveragePlan plan;
  plan.grid = std::make_shared<const Grid>(f.grid);
  auto detail = std::make_shared<OarpDetail>();
  detail->ranks = f.partition.ranks;
  plan.detail = detail;
  plan.path = cost.BuildPath(tour.vertices);
  plan.stats = ComputePathStats(plan.path, robot);
  plan.stats.num_ranks = static_cast<int64_t>(f.partition.ranks.size());
  return plan;
}

// The rank tour's own invariants: ranks driven once each, the path in free
// cells across no barrier.
std::string CheckRankPlan(const CoveragePlan& plan) {
  std::string err = testing::CheckOarpDetail(plan, *plan.grid);
  if (!err.empty()) return err;
  return testing::CheckPathStaysFree(*plan.grid, plan.path);
}

using testing::kRooms;

TEST(TransitionTable, PathsConnectEndpointsAndStayFree) {
  Fixture f = Make(Grid::FromAscii(kRooms));
  const int e = f.table->num_endpoints();
  ASSERT_EQ(e, static_cast<int>(2 * f.partition.ranks.size()));
  for (int a = 0; a < e; ++a) {
    for (int b = 0; b < e; ++b) {
      ASSERT_TRUE(f.table->Reachable(a, b));
      std::vector<CellIndex> cells;
      f.table->AppendPath(a, b, &cells);
      ASSERT_EQ(cells.front(), f.table->endpoint(a));
      ASSERT_EQ(cells.back(), f.table->endpoint(b));
      std::vector<Waypoint> wps;
      for (const CellIndex& c : cells)
        wps.push_back(
            {f.grid.CellCenter(c).x, f.grid.CellCenter(c).y, 0, SegmentKind::kTransition, -1});
      ASSERT_EQ(testing::CheckPathStaysFree(f.grid, wps), "") << a << "->" << b;
    }
  }
  EXPECT_GT(f.table->MemoryBytes(), 0u);
}

TEST(RankTour, TourTimeEqualsPathDuration) {
  Fixture f = Make(Grid::FromAscii(kRooms, 0.8));
  RobotModel robot;
  robot.start = Pose2{0.5, 0.3, 1.0};
  auto cost = RankTourCost::Create(f.grid, f.partition.ranks, *f.table, robot, StopToken());
  ASSERT_TRUE(cost.ok()) << cost.status();
  for (bool gtsp : {false, true}) {
    absl::StatusOr<TourOrder> tour = gtsp ? GtspOrderer({0.3, 1, 1}).Order(*cost, StopToken())
                                          : GreedyOrderer().Order(*cost, StopToken());
    ASSERT_TRUE(tour.ok()) << tour.status();
    ASSERT_EQ(tour->vertices.size(), f.partition.ranks.size());
    CoveragePlan plan = AsPlan(f, *cost, *tour, robot);
    EXPECT_EQ(CheckRankPlan(plan), "");
    EXPECT_NEAR(plan.stats.estimated_duration_s, tour->cost, 1e-6);
    // Ends back at the start pose.
    EXPECT_NEAR(plan.path.back().x, 0.5, 1e-9);
    EXPECT_NEAR(plan.path.back().y, 0.3, 1e-9);
  }
}

TEST(RankTour, GtspNoWorseThanGreedy) {
  for (uint32_t seed = 0; seed < 5; ++seed) {
    Fixture f = Make(testing::RandomGrid(14, 18, 0.85, seed));
    // Random grids may be disconnected: keep it simple and skip those.
    int32_t comps = 0;
    FreeComponents(f.grid, &comps);
    if (comps != 1) continue;
    RobotModel robot;
    auto cost = RankTourCost::Create(f.grid, f.partition.ranks, *f.table, robot, StopToken());
    ASSERT_TRUE(cost.ok()) << cost.status();
    auto greedy = GreedyOrderer().Order(*cost, StopToken());
    auto gtsp = GtspOrderer({0.5, seed, 1}).Order(*cost, StopToken());
    ASSERT_TRUE(greedy.ok() && gtsp.ok());
    EXPECT_LE(gtsp->cost, greedy->cost + 1e-9);
    EXPECT_EQ(CheckRankPlan(AsPlan(f, *cost, *gtsp, robot)), "");
  }
}

TEST(RankTour, EndPoseIsHonoured) {
  Fixture f = Make(Grid::FromAscii(kRooms, 1.0));
  RobotModel robot;
  robot.start = Pose2{0.5, 0.5, 0.0};
  robot.end = Pose2{19.5, 9.5, 0.0};
  auto cost = RankTourCost::Create(f.grid, f.partition.ranks, *f.table, robot, StopToken());
  ASSERT_TRUE(cost.ok()) << cost.status();
  auto tour = GtspOrderer({0.3, 3, 1}).Order(*cost, StopToken());
  ASSERT_TRUE(tour.ok());
  CoveragePlan plan = AsPlan(f, *cost, *tour, robot);
  EXPECT_NEAR(plan.path.back().x, 19.5, 1e-9);
  EXPECT_NEAR(plan.path.back().y, 9.5, 1e-9);
  EXPECT_NEAR(plan.stats.estimated_duration_s, tour->cost, 1e-6);
}

TEST(RankTour, StartPoseInBlockedCellJoinsTheNearestAdjacentFreeCell) {
  // A dock against a wall: the pose lies in the '##' block (rows 6..7, cols
  // 3..4); the robot first moves onto an adjacent free cell, then the path
  // stays in free cells and ends back at the pose.
  Fixture f = Make(Grid::FromAscii(kRooms, 1.0));
  RobotModel robot;
  robot.start = Pose2{3.4, 7.5, 0.0};
  auto cost = RankTourCost::Create(f.grid, f.partition.ranks, *f.table, robot, StopToken());
  ASSERT_TRUE(cost.ok()) << cost.status();
  auto tour = GtspOrderer({0.2, 1, 1}).Order(*cost, StopToken());
  ASSERT_TRUE(tour.ok()) << tour.status();
  CoveragePlan plan = AsPlan(f, *cost, *tour, robot);
  ASSERT_GE(plan.path.size(), 3u);
  EXPECT_NEAR(plan.path[0].x, 3.4, 1e-9);
  EXPECT_NEAR(plan.path[0].y, 7.5, 1e-9);
  // Nearest free centre to (3.4, 7.5) is (2.5, 7.5), the cell left of the block.
  EXPECT_NEAR(plan.path[1].x, 2.5, 1e-9);
  EXPECT_NEAR(plan.path[1].y, 7.5, 1e-9);
  const std::vector<Waypoint> inner(plan.path.begin() + 1, plan.path.end() - 1);
  EXPECT_EQ(testing::CheckPathStaysFree(f.grid, inner), "");
  EXPECT_NEAR(plan.path.back().x, 3.4, 1e-9);
  EXPECT_NEAR(plan.stats.estimated_duration_s, tour->cost, 1e-6);
}

TEST(RankTour, PoseFarFromFreeCellsIsInvalidArgument) {
  Fixture f = Make(Grid::FromAscii(kRooms, 1.0));
  for (Pose2 pose : {Pose2{-5.0, -5.0, 0.0}, Pose2{40.0, 3.0, 0.0}, Pose2{1e300, -1e300, 0.0},
                     Pose2{-1e300, 1e18, 0.0}}) {
    RobotModel robot;
    robot.start = pose;
    auto cost = RankTourCost::Create(f.grid, f.partition.ranks, *f.table, robot, StopToken());
    EXPECT_EQ(cost.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(cost.status().message().find("start pose"), std::string::npos) << cost.status();
    RobotModel robot2;
    robot2.end = pose;
    cost = RankTourCost::Create(f.grid, f.partition.ranks, *f.table, robot2, StopToken());
    EXPECT_EQ(cost.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(cost.status().message().find("end pose"), std::string::npos) << cost.status();
  }
}

}  // namespace
}  // namespace covplan
