#include "planner/assembly/plan_coverage.h"

#include <cmath>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/plan/svg.h"
#include "tests/testing/oarp_options.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

// A 12 m x 8 m map at 0.05 m/px: walls around, a room divider with a door,
// a table-sized hole.
OccupancyMap OfficeMap() {
  const double res = 0.05;
  OccupancyMap m(240, 160, res, {-1.0, 2.0});
  for (int r = 0; r < 160; ++r) {
    for (int c = 0; c < 240; ++c) {
      const bool wall = r < 4 || r >= 156 || c < 4 || c >= 236;
      const bool divider = c >= 118 && c < 122 && !(r >= 60 && r < 100);
      const bool table = r >= 30 && r < 50 && c >= 40 && c < 80;
      m.set(r, c, wall || divider || table ? CellState::kOccupied : CellState::kFree);
    }
  }
  return m;
}

TEST(BuildGrid, MoreThanHalfFreeRule) {
  // 4x4 pixels, cell = 2 px: top-left cell has exactly 2 of 4 free (not free),
  // bottom-right has 3 of 4 (free).
  OccupancyMap m(4, 4, 0.5, {0, 0});
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.set(r, c, CellState::kOccupied);
  m.set(3, 0, CellState::kFree);
  m.set(3, 1, CellState::kFree);
  m.set(0, 2, CellState::kFree);
  m.set(0, 3, CellState::kFree);
  m.set(1, 3, CellState::kFree);
  GridOptions opt;
  opt.cell_size = 1.0;
  auto g = BuildGrid(m, opt);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->rows(), 2);
  EXPECT_EQ(g->cols(), 2);
  EXPECT_FALSE(g->IsFree(1, 0));  // exactly half
  EXPECT_TRUE(g->IsFree(0, 1));   // three quarters
  EXPECT_EQ(g->CountFree(), 1);
}

TEST(BuildGrid, NonIntegerCellSizeUsesFractionalOverlap) {
  OccupancyMap m(10, 10, 0.1, {0, 0});
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 10; ++c) m.set(r, c, CellState::kFree);
  GridOptions opt;
  opt.cell_size = 0.3;  // 3 px; 4th column cell is 1/3 inside the map
  auto g = BuildGrid(m, opt);
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(g->cols(), 4);
  EXPECT_TRUE(g->IsFree(0, 2));
  EXPECT_FALSE(g->IsFree(0, 3));
  EXPECT_NEAR(CoveredFreeAreaRatio(m, *g), 0.81, 1e-9);
}

TEST(PlanCoverage, OfficeMapConforms) {
  for (TourSolver tour : {TourSolver::kGreedy, TourSolver::kGtsp}) {
    PlanOptions opt;
    opt.options = testing::OarpOptionsWith(tour);
    opt.time_limit_s = 0.3;
    auto result = PlanCoverageWithArea(OfficeMap(), opt);
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_EQ(testing::CheckOarpConformance(*result, opt.robot), "");
    const CoveragePlan* plan = &result->plan;
    EXPECT_EQ(plan->planner, "oarp");
    EXPECT_GT(plan->stats.covered_free_area_ratio, 0.8);
    EXPECT_LE(plan->stats.covered_free_area_ratio, 1.0);
    EXPECT_GT(plan->stats.estimated_duration_s, 0.0);
    EXPECT_EQ(plan->stats.grid_rows, 10);
    EXPECT_EQ(plan->stats.grid_cols, 15);
    const std::string svg = RenderPlanSvg(*plan, nullptr);
    EXPECT_THAT(svg, HasSubstr("<svg"));
    EXPECT_THAT(svg, HasSubstr("</svg>"));
  }
}

TEST(PlanCoverage, ExactSolversGiveSameRankCount) {
  PlanOptions a, b, c, d;  // a: the default (push-relabel)
  a.options = testing::OarpOptionsWith(TourSolver::kGreedy);
  b.options = testing::OarpOptionsWith(TourSolver::kGreedy, PartitionSolver::kLp);
  c.options = testing::OarpOptionsWith(TourSolver::kGreedy, PartitionSolver::kMinCut);
  d.options = testing::OarpOptionsWith(TourSolver::kGreedy, PartitionSolver::kMatching);
  auto pa = PlanCoverage(OfficeMap(), a);
  auto pb = PlanCoverage(OfficeMap(), b);
  auto pc = PlanCoverage(OfficeMap(), c);
  auto pd = PlanCoverage(OfficeMap(), d);
  ASSERT_TRUE(pa.ok() && pb.ok() && pc.ok() && pd.ok());
  EXPECT_EQ(pa->detail_as<OarpDetail>()->ranks.size(), pb->detail_as<OarpDetail>()->ranks.size());
  EXPECT_EQ(pc->detail_as<OarpDetail>()->ranks.size(), pb->detail_as<OarpDetail>()->ranks.size());
  EXPECT_EQ(pd->detail_as<OarpDetail>()->ranks.size(), pb->detail_as<OarpDetail>()->ranks.size());
  EXPECT_EQ(pa->stats.partition_solver, "pushrelabel");
  EXPECT_EQ(pb->stats.partition_solver, "lp");
  EXPECT_EQ(pc->stats.partition_solver, "mincut");
  EXPECT_EQ(pd->stats.partition_solver, "matching");
}

TEST(PlanCoverage, BadInputIsInvalidArgument) {
  struct Case {
    double tool;
    const char* message;
  };
  for (const Case& c : {Case{NAN, "robot.tool_width_m"}, Case{0.0, "robot.tool_width_m"},
                        Case{-0.8, "robot.tool_width_m"}, Case{0.01, "narrower than one map pixel"},
                        Case{20.0, "wider than the map"}}) {
    PlanOptions opt;
    opt.robot.tool_width_m = c.tool;
    auto plan = PlanCoverage(OfficeMap(), opt);
    EXPECT_EQ(plan.status().code(), absl::StatusCode::kInvalidArgument) << c.tool;
    EXPECT_THAT(plan.status().message(), HasSubstr(c.message)) << c.tool;
  }
  OccupancyMap blocked(50, 50, 0.05, {0, 0});  // all unknown
  auto plan = PlanCoverage(blocked, PlanOptions());
  EXPECT_EQ(plan.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(plan.status().message(), HasSubstr("no free cell"));
  PlanOptions neg;
  neg.time_limit_s = -1;
  EXPECT_EQ(PlanCoverage(OfficeMap(), neg).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(PlanCoverage, DisconnectedAreasAreReportedNotPlanned) {
  OccupancyMap m = OfficeMap();
  // A 1.6 m thick wall splits the map: the smaller side becomes unreachable.
  for (int r = 0; r < 160; ++r)
    for (int c = 150; c < 182; ++c) m.set(r, c, CellState::kOccupied);
  PlanOptions opt;
  opt.options = testing::OarpOptionsWith(TourSolver::kGreedy);
  auto plan = PlanCoverageWithArea(m, opt);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_GT(plan->plan.stats.unreachable_free_cells, 0);
  EXPECT_EQ(testing::CheckOarpConformance(*plan, opt.robot), "");
}

}  // namespace
}  // namespace covplan

namespace covplan {
namespace {

TEST(BuildGrid, ThinWallBecomesBarrier) {
  // 4 m x 2 m free room at 0.05 m/px with a 0.1 m wall at x = 2 m, open
  // only in the top 0.4 m: the wall is far thinner than a 0.8 m cell.
  OccupancyMap m(80, 40, 0.05, {0, 0});
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 80; ++c)
      m.set(r, c, (c == 39 || c == 40) && r < 32 ? CellState::kOccupied : CellState::kFree);
  GridOptions opt;
  opt.cell_size = 0.8;
  auto g = BuildGrid(m, opt);
  ASSERT_TRUE(g.ok());
  ASSERT_EQ(g->cols(), 5);
  // Column 2 (1.6..2.4 m) contains the wall but is >50 % free.
  EXPECT_TRUE(g->IsFree(0, 2));
  EXPECT_GT(g->CountBarriers(), 0);
  // No horizontal link across the wall in the walled rows.
  EXPECT_FALSE(g->Passable(0, 2, 0, 1) && g->Passable(0, 1, 0, 1));
  opt.thin_wall_barriers = false;
  EXPECT_EQ(BuildGrid(m, opt)->CountBarriers(), 0);

  PlanOptions po;
  po.options = testing::OarpOptionsWith(TourSolver::kGreedy);
  auto plan = PlanCoverageWithArea(m, po);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(testing::CheckOarpConformance(*plan, po.robot), "");
}

}  // namespace
}  // namespace covplan
