// `covplan compare`: every named planner plans the same map, the rows agree
// with the engine's own plans, redundancy is counted from the path, unknown
// names list the registered planners.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "client/compare_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/grid/map_io.h"
#include "planner/stc/stc_planner.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

MapSource ShippedSource(const std::string& name) {
  MapSource s;
  s.map_id = name;
  s.load = [name]() -> absl::StatusOr<SiteMap> {
    absl::StatusOr<OccupancyMap> map =
        LoadMapFile(absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/", name), MapLoadOptions());
    if (!map.ok()) return map.status();
    SiteMap site;
    site.raster = std::make_shared<const OccupancyMap>(*std::move(map));
    return site;
  };
  return s;
}

TEST(CompareCommand, RowsAgreeWithTheEnginesPlans) {
  const PlannerRegistry registry = BuiltinPlanners();
  PlanRequest request;
  request.common.robot.tool_width_m = 0.8;
  request.common.time_limit_s = 30;  // OARP's default effort converges long before
  absl::StatusOr<std::vector<ComparisonRow>> rows = ComparePlanners(
      registry, ShippedSource("sample_office.yaml"), {"stc", "oarp"}, request, EngineLimits{});
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 2u);
  EXPECT_EQ((*rows)[0].planner, "stc");
  EXPECT_EQ((*rows)[1].planner, "oarp");
  for (const ComparisonRow& row : *rows) {
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, EngineLimits{});
    PlanRequest r = request;
    r.planner = row.planner;
    absl::StatusOr<EngineResult> plan = engine.Plan(ShippedSource("sample_office.yaml"), r);
    ASSERT_TRUE(plan.ok());
    const PlanStats& s = plan->plan.stats;
    EXPECT_EQ(row.turns, s.num_turns);
    EXPECT_DOUBLE_EQ(row.length_m, s.coverage_length_m + s.transition_length_m);
    EXPECT_DOUBLE_EQ(row.duration_s, s.estimated_duration_s);
    EXPECT_EQ(row.covered_cells, row.cells_to_cover);
    EXPECT_DOUBLE_EQ(row.covered_free_area_ratio, s.covered_free_area_ratio);
    EXPECT_EQ(row.redundant_cells, CountRedundantCells(*plan->area, plan->plan.path));
    EXPECT_GT(row.planning_ms, 0.0);
    // Without regions every drive cell is to cover: the whole path repeats at
    // least the cells STC reports covered twice while covering.
    if (const StcDetail* stc = plan->plan.detail_as<StcDetail>()) {
      EXPECT_GE(row.redundant_cells, stc->subcells_covered_twice);
      EXPECT_GT(stc->subcells_covered_twice, 0);  // the office has partly free coarse cells
    }
  }
  const std::string md = ComparisonMarkdown(*rows, "office", true);
  EXPECT_THAT(md, HasSubstr("| map | planner | turns |"));
  EXPECT_THAT(md, HasSubstr("| office | stc |"));
  const std::string json = ComparisonJson(*rows, "maps/sample_office.yaml", 0.8);
  EXPECT_THAT(json, HasSubstr("\"planner\": \"oarp\""));
  EXPECT_THAT(json, HasSubstr("\"redundant_cells\": "));
}

TEST(CompareCommand, RedundantCellsCountCellsEnteredTwice) {
  auto area = std::make_shared<CoverageArea>();
  area->drive = std::make_shared<const Grid>(Grid::FromAscii({"....", "...."}));
  area->cover = area->drive;
  // Along the bottom row and back along it: cells (0,0)..(0,2) are entered twice.
  std::vector<Waypoint> path = {{0.5, 0.5, 0, SegmentKind::kStart, -1},
                                {3.5, 0.5, 0, SegmentKind::kCoverage, -1},
                                {0.5, 0.5, M_PI, SegmentKind::kTransition, -1}};
  EXPECT_EQ(CountRedundantCells(*area, path), 3);
  path.pop_back();
  EXPECT_EQ(CountRedundantCells(*area, path), 0);
}

TEST(CompareCommand, UnknownAlgorithmsListTheRegisteredOnes) {
  const PlannerRegistry registry = BuiltinPlanners();
  absl::StatusOr<std::vector<ComparisonRow>> rows =
      ComparePlanners(registry, ShippedSource("small_rooms.yaml"), {"oarp", "spiral"},
                      PlanRequest(), EngineLimits{});
  EXPECT_EQ(rows.status().code(), absl::StatusCode::kInvalidArgument);
  // Every registered planner is listed (others join after merges).
  EXPECT_THAT(std::string(rows.status().message()),
              HasSubstr("unknown algorithm 'spiral'; registered: "));
  for (const std::string& name : registry.Names()) {
    EXPECT_THAT(std::string(rows.status().message()), HasSubstr(name));
  }

  const std::string json =
      (std::filesystem::temp_directory_path() / absl::StrCat("cmp_", ::getpid(), ".json")).string();
  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml");
  EXPECT_EQ(RunCompareCommand(
                {"--map", map, "--algorithms", "stc,oarp", "--json", json, "--time-limit", "0.3"}),
            0);
  std::ifstream in(json);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_THAT(ss.str(), HasSubstr("\"planner\": \"stc\""));
  EXPECT_THAT(ss.str(), HasSubstr("\"planner\": \"oarp\""));
  std::filesystem::remove(json);
  EXPECT_NE(RunCompareCommand({"--map", map, "--algorithms", "stc,nope"}), 0);
  EXPECT_NE(RunCompareCommand({"--algorithms", "stc"}), 0);
}

// --robots K: each planner as a K-robot fleet, both divisions, each row's
// makespan at least its lower bound and every cell swept.
TEST(CompareCommand, RobotsCompareEachPlannerAsAFleet) {
  const PlannerRegistry registry = BuiltinPlanners();
  PlanRequest request;
  request.common.robot.tool_width_m = 0.8;
  request.common.time_limit_s = 0.5;
  absl::StatusOr<std::vector<FleetComparisonRow>> rows = CompareFleets(
      registry, ShippedSource("small_rooms.yaml"), {"stc", "oarp"}, request, 2, EngineLimits{});
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 2u);
  EXPECT_EQ((*rows)[0].planner, "stc");
  EXPECT_EQ((*rows)[1].planner, "oarp");
  for (const FleetComparisonRow& row : *rows) {
    SCOPED_TRACE(row.planner);
    EXPECT_EQ(row.robots, 2);
    EXPECT_GT(row.lower_bound_s, 0.0);
    EXPECT_GE(row.makespan_s, row.lower_bound_s);
    EXPECT_NEAR(row.gap, row.makespan_s / row.lower_bound_s - 1.0, 1e-9);
    EXPECT_GE(row.equal_area_makespan_s, row.lower_bound_s);
    EXPECT_EQ(row.covered_cells, row.cells_to_cover);
    EXPECT_GT(row.planning_ms, 0.0);
  }
  EXPECT_THAT(FleetComparisonTable(*rows), HasSubstr("equal_area_s"));
  EXPECT_THAT(FleetComparisonMarkdown(*rows, "rooms", true), HasSubstr("| rooms | stc | 2 | "));
  EXPECT_THAT(FleetComparisonJson(*rows, "maps/small_rooms.yaml", 0.8),
              HasSubstr("\"equal_area_makespan_s\": "));

  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml");
  EXPECT_EQ(RunCompareCommand(
                {"--map", map, "--algorithms", "stc", "--robots", "2", "--time-limit", "0.3"}),
            0);
  EXPECT_NE(RunCompareCommand({"--map", map, "--robots", "0"}), 0);
  EXPECT_NE(RunCompareCommand({"--map", map, "--robots", "2", "--algorithms", "nope"}), 0);
}

}  // namespace
}  // namespace covplan
