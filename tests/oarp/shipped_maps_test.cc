// Every map shipped in maps/: the LP, the min-cut and the matching agree on
// the optimal rank count (at several tool widths, thin-wall barriers on), and
// the full plan conforms.
#include <string>

#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/map_io.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

class ShippedMap : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedMap, LpEqualsMinCutAndPlanConforms) {
  const std::string path = std::string(COVPLAN_SOURCE_DIR) + "/maps/" + GetParam();
  absl::StatusOr<OccupancyMap> map = LoadMapFile(path, MapLoadOptions());
  ASSERT_TRUE(map.ok()) << map.status();
  for (double tool : {0.5, 0.8, 1.2}) {
    GridOptions go;
    go.cell_size = tool;
    absl::StatusOr<Grid> grid = BuildGrid(*map, go);
    ASSERT_TRUE(grid.ok()) << grid.status();
    auto cut = MinCutPartitioner().Partition(*grid, StopToken());
    auto lp = LpPartitioner().Partition(*grid, StopToken());
    auto matching = MatchingPartitioner().Partition(*grid, StopToken());
    ASSERT_TRUE(cut.ok()) << cut.status();
    ASSERT_TRUE(lp.ok()) << lp.status();
    ASSERT_TRUE(matching.ok()) << matching.status();
    EXPECT_EQ(cut->ranks.size(), lp->ranks.size()) << GetParam() << " tool " << tool;
    EXPECT_EQ(matching->ranks.size(), lp->ranks.size()) << GetParam() << " tool " << tool;
    EXPECT_EQ(testing::CheckExactCover(*grid, cut->ranks), "");
    EXPECT_EQ(testing::CheckExactCover(*grid, matching->ranks), "");
  }
  PlanOptions opt;
  opt.time_limit_s = 0.3;
  absl::StatusOr<EngineResult> plan = PlanCoverageWithArea(*map, opt);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(testing::CheckOarpConformance(*plan, opt.robot), "");
  EXPECT_GT(plan->plan.stats.covered_free_area_ratio, 0.5);
}

TEST_P(ShippedMap, DriveLineNeverCrossesAnObstaclePixel) {
  // Cells are free when most of their area is: furniture smaller than a cell
  // hides inside free cells. Coverage and transitions must still miss it.
  const std::string path = std::string(COVPLAN_SOURCE_DIR) + "/maps/" + GetParam();
  absl::StatusOr<OccupancyMap> map = LoadMapFile(path, MapLoadOptions());
  ASSERT_TRUE(map.ok()) << map.status();
  for (double tool : {0.5, 0.8, 1.2}) {
    PlanOptions opt;
    opt.time_limit_s = 0.2;
    opt.robot.tool_width_m = tool;
    absl::StatusOr<CoveragePlan> plan = PlanCoverage(*map, opt);
    ASSERT_TRUE(plan.ok()) << plan.status();
    EXPECT_EQ(testing::CheckPathAvoidsMapObstacles(*map, plan->path), "")
        << GetParam() << " tool " << tool;
  }
}

INSTANTIATE_TEST_SUITE_P(Maps, ShippedMap,
                         ::testing::Values("sample_office.yaml", "sample_office_furnished.yaml",
                                           "small_rooms.yaml"));

}  // namespace
}  // namespace covplan
