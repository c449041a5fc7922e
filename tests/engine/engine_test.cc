// The engine: every registered planner passes the one conformance suite;
// planners are selected by name with their own options; Termination says how
// the search ended; per-map artifacts are built once.
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/engine/engine.h"
#include "planner/grid/map_io.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

OccupancyMap Load(const std::string& name) { return testing::LoadShippedMap(name); }

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

PlanRequest Request(const std::string& planner, double tool) {
  PlanRequest r;
  r.planner = planner;
  r.common.robot.tool_width_m = tool;
  r.common.time_limit_s = 0.3;
  return r;
}

class EveryPlanner : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryPlanner, ConformsOnShippedMapsWithAndWithoutZones) {
  const PlannerRegistry registry = BuiltinPlanners();
  for (const std::string map_name : {"small_rooms.yaml", "sample_office_furnished.yaml"}) {
    const OccupancyMap map = Load(map_name);
    for (double tool : {0.5, 0.9}) {
      for (bool zones : {false, true}) {
        SCOPED_TRACE(map_name + " tool " + std::to_string(tool) + (zones ? " zones" : ""));
        LocalArtifactCache cache;
        PlanningEngine engine(&registry, &cache, EngineLimits{});
        PlanRequest r = Request(GetParam(), tool);
        if (zones) {
          r.no_go = {{{{2.1, 1.3}, {3.7, 1.6}, {3.2, 3.1}, {2.1, 1.3}}, {}}};
          r.regions = {{{{0.0, 0.0}, {7.2, 0.0}, {7.2, 6.0}, {0.0, 6.0}, {0.0, 0.0}}, {}}};
        }
        absl::StatusOr<EngineResult> result = engine.Plan(SourceOf(map, map_name), r);
        ASSERT_TRUE(result.ok()) << result.status();
        EXPECT_EQ(result->plan.planner, GetParam());
        EXPECT_EQ(
            testing::CheckPlanConformance(result->plan, *result->area, r.common.robot, r.no_go),
            "");
        EXPECT_GT(result->plan.stats.covered_cells, 0);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryPlanner, ::testing::ValuesIn(BuiltinPlanners().Names()));

TEST(Registry, SelectsByNameAndRefusesUnknownPlannersAndForeignOptions) {
  const PlannerRegistry registry = BuiltinPlanners();
  EXPECT_THAT(registry.Names(), ::testing::Contains("oarp"));
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const OccupancyMap map = Load("small_rooms.yaml");
  PlanRequest r = Request("boustrophedon-typo", 0.8);
  absl::StatusOr<EngineResult> result = engine.Plan(SourceOf(map, "m"), r);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("registered: boustrophedon, oarp"));

  struct OtherOptions final : PlannerOptions {
    absl::Status Validate() const override { return absl::OkStatus(); }
    std::string CacheText() const override { return "other"; }
  };
  r = Request("oarp", 0.8);
  r.options = std::make_shared<OtherOptions>();
  result = engine.Plan(SourceOf(map, "m"), r);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("OARP options"));

  auto oarp = std::make_shared<OarpOptions>();
  oarp->tour_solver = static_cast<TourSolver>(7);
  r.options = oarp;
  result = engine.Plan(SourceOf(map, "m"), r);
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(result.status().message()), HasSubstr("oarp.tour_solver"));
}

TEST(Termination, SaysWhetherTheSearchConvergedOrWhichLimitStoppedIt) {
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const OccupancyMap map = Load("sample_office.yaml");
  const MapSource source = SourceOf(map, "office");

  PlanRequest r = Request("oarp", 0.8);
  r.common.time_limit_s = 30;  // the default effort stops by itself long before
  absl::StatusOr<EngineResult> converged = engine.Plan(source, r);
  ASSERT_TRUE(converged.ok()) << converged.status();
  EXPECT_EQ(converged->plan.termination.reason, TerminationReason::kConverged);
  EXPECT_EQ(converged->plan.termination.limit, TerminationLimit::kNone);
  EXPECT_FALSE(converged->plan.stats.tour_cut_short);

  auto thorough = std::make_shared<OarpOptions>();
  thorough->tour_effort = GtspEffort::kThorough;  // improves until the budget is spent
  r.options = thorough;
  r.common.time_limit_s = 0.2;
  absl::StatusOr<EngineResult> timed = engine.Plan(source, r);
  ASSERT_TRUE(timed.ok()) << timed.status();
  EXPECT_EQ(timed->plan.termination.reason, TerminationReason::kFeasibleLimitReached);
  EXPECT_EQ(timed->plan.termination.limit, TerminationLimit::kTime);
  EXPECT_FALSE(timed->plan.stats.tour_cut_short);  // old meaning: the caller's deadline

  r.common.time_limit_s = 30;
  r.common.stop = StopToken::WithTimeout(absl::Milliseconds(300));  // artifacts are cached
  absl::StatusOr<EngineResult> deadline = engine.Plan(source, r);
  ASSERT_TRUE(deadline.ok()) << deadline.status();
  EXPECT_EQ(deadline->plan.termination.limit, TerminationLimit::kDeadline);
  EXPECT_TRUE(deadline->plan.stats.tour_cut_short);
  EXPECT_EQ(testing::CheckOarpConformance(*deadline, r.common.robot), "");
}

TEST(Artifacts, AreBuiltOnceAndPrepareWarmsThem) {
  const PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  const OccupancyMap map = Load("small_rooms.yaml");
  int loads = 0;
  MapSource source;
  source.map_id = "rooms";
  source.load = [&]() -> absl::StatusOr<SiteMap> {
    ++loads;
    SiteMap site;
    site.raster = std::make_shared<const OccupancyMap>(map);
    return site;
  };
  PlanRequest r = Request("oarp", 0.6);
  r.common.time_limit_s = 60;  // converges long before: the same seed gives the same plan
  ASSERT_TRUE(engine.Prepare(source, r).ok());
  EXPECT_EQ(loads, 1);
  EXPECT_EQ(cache.size(), 5u);  // grid, area, floor, partition, transitions
  absl::StatusOr<EngineResult> a = engine.Plan(source, r);
  absl::StatusOr<EngineResult> b = engine.Plan(source, r);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(loads, 1);
  EXPECT_TRUE(a->plan.stats.decomposition_cached);
  EXPECT_EQ(a->area.get(), b->area.get());  // shared, immutable
  // Same seed, converged search: the same plan.
  ASSERT_EQ(a->plan.path.size(), b->plan.path.size());
  for (size_t i = 0; i < a->plan.path.size(); ++i) {
    EXPECT_EQ(a->plan.path[i].x, b->plan.path[i].x);
    EXPECT_EQ(a->plan.path[i].y, b->plan.path[i].y);
  }
  // A loader failure is the caller's error, not cached.
  MapSource missing;
  missing.map_id = "gone";
  missing.load = []() -> absl::StatusOr<SiteMap> { return absl::NotFoundError("map gone"); };
  EXPECT_EQ(engine.Plan(missing, r).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(cache.size(), 7u);  // the 5 artifacts + the remembered tour and plan
}

// The site checks are the engine's, so every entry point (the server,
// `covplan plan --local`, PlanCoverage) refuses such maps alike.
TEST(Engine, RefusesMapsNoRobotCanPlanOn) {
  PlanOptions o;
  o.robot.tool_width_m = 0.8;
  const absl::Status coarse = PlanCoverage(OccupancyMap(4, 4, 5000.0, {0.0, 0.0}), o).status();
  EXPECT_EQ(coarse.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(coarse.message(), "map resolution 5000 m/px is outside [0.0001, 1000] m/px");
  const absl::Status far = PlanCoverage(OccupancyMap(40, 40, 0.1, {2e7, 0.0}), o).status();
  EXPECT_EQ(far.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(far.message(),
            "map origin/extent (2e+07, 0) m is beyond 1e+07 m from the map frame's origin");
}

}  // namespace
}  // namespace covplan
