// The "stc" planner through the engine: conformance on shipped maps with
// regions, no-go zones and start/end poses for every tree variant; every
// sub-cell to cover swept; options checked by the engine.
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"
#include "planner/stc/stc_planner.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

MapSource SourceOf(const OccupancyMap& map, const std::string& id) {
  MapSource s;
  s.map_id = id;
  s.load = [&map]() -> absl::StatusOr<SiteMap> {
    SiteMap site;
    site.raster = std::make_shared<const OccupancyMap>(map);
    return site;
  };
  return s;
}

struct Variant {
  StcTreeMethod tree;
  SweepDirection direction;
};

TEST(StcEngine, ConformsOnShippedMapsWithZonesAndPoses) {
  const PlannerRegistry registry = BuiltinPlanners();
  for (const std::string name :
       {"small_rooms.yaml", "sample_office.yaml", "sample_office_furnished.yaml"}) {
    const OccupancyMap map = testing::LoadShippedMap(name);
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, EngineLimits{});
    for (const Variant v : {Variant{StcTreeMethod::kDfs, SweepDirection::kHorizontal},
                            Variant{StcTreeMethod::kPrim, SweepDirection::kHorizontal},
                            Variant{StcTreeMethod::kPrim, SweepDirection::kVertical}}) {
      for (int setup = 0; setup < 3; ++setup) {
        SCOPED_TRACE(absl::StrFormat("%s tree %d dir %d setup %d", name, static_cast<int>(v.tree),
                                     static_cast<int>(v.direction), setup));
        PlanRequest r;
        r.planner = "stc";
        r.common.robot.tool_width_m = setup == 2 ? 0.45 : 0.8;
        auto options = std::make_shared<StcOptions>();
        options->tree = v.tree;
        options->sweep_direction = v.direction;
        r.options = options;
        if (setup >= 1) {
          r.no_go = {{{{2.1, 1.3}, {3.7, 1.6}, {3.2, 3.1}, {2.1, 1.3}}, {}}};
          r.regions = {{{{0.0, 0.0}, {7.2, 0.0}, {7.2, 6.0}, {0.0, 6.0}, {0.0, 0.0}}, {}}};
        }
        Pose2 start, end;
        if (setup == 2) {
          // Poses inside free cells of the drive grid (first and last free cell).
          absl::StatusOr<std::shared_ptr<const CoverageArea>> area =
              engine.AreaFor(SourceOf(map, name), r);
          ASSERT_TRUE(area.ok()) << area.status();
          const Grid& drive = *(*area)->drive;
          int64_t first = -1, last = -1;
          for (int64_t i = 0; i < drive.size(); ++i) {
            if (!drive.free_flags()[i]) continue;
            if (first < 0) first = i;
            last = i;
          }
          const Point2 a = drive.CellCenter(drive.FromIndex(first)),
                       b = drive.CellCenter(drive.FromIndex(last));
          start = {a.x + 0.1, a.y - 0.05, 0.3};
          end = {b.x - 0.05, b.y, 0.0};
          r.common.robot.start = start;
          r.common.robot.end = end;
        }
        absl::StatusOr<EngineResult> result = engine.Plan(SourceOf(map, name), r);
        ASSERT_TRUE(result.ok()) << result.status();
        EXPECT_EQ(result->plan.planner, "stc");
        EXPECT_EQ(
            testing::CheckPlanConformance(result->plan, *result->area, r.common.robot, r.no_go),
            "");
        EXPECT_EQ(testing::CheckPathAvoidsMapObstacles(map, result->plan.path, setup == 2 ? 1 : 0),
                  "");
        EXPECT_EQ(result->plan.stats.covered_cells, result->plan.stats.free_cells);
        const StcDetail* d = result->plan.detail_as<StcDetail>();
        ASSERT_NE(d, nullptr);
        EXPECT_EQ(d->tree, v.tree);
        EXPECT_GE(d->trees, 1);
        EXPECT_EQ(d->discarded_cells, 0);
        EXPECT_GE(d->coarse_cells, d->full_coarse_cells);
        if (setup == 2) {
          EXPECT_DOUBLE_EQ(result->plan.path.front().x, start.x);
          EXPECT_DOUBLE_EQ(result->plan.path.front().y, start.y);
          EXPECT_DOUBLE_EQ(result->plan.path.back().x, end.x);
          EXPECT_DOUBLE_EQ(result->plan.path.back().y, end.y);
        }
        EXPECT_EQ(result->plan.termination.reason, TerminationReason::kConverged);
      }
    }
  }
}

TEST(StcEngine, BadOptionsAreInvalidArgument) {
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const OccupancyMap map = testing::LoadShippedMap("small_rooms.yaml");
  PlanRequest r;
  r.planner = "stc";
  auto bad = std::make_shared<StcOptions>();
  bad->tree = static_cast<StcTreeMethod>(4);
  r.options = bad;
  absl::StatusOr<EngineResult> result = engine.Plan(SourceOf(map, "m"), r);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("stc.tree"));
  r.options = std::make_shared<OarpOptions>();
  result = engine.Plan(SourceOf(map, "m"), r);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("STC options"));
  EXPECT_THAT(registry.Names(), ::testing::Contains("stc"));
}

}  // namespace
}  // namespace covplan
