// Remembered plans (planner/engine/plan_memory.h): an identical request is
// answered from memory with the same path; any change to the map, zones,
// robot, options or seed is not; a new start pose warm-starts and still
// covers every cell from that pose; without memory (or with a fresh cache)
// the same seed gives the same plan.
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"
#include "planner/engine/plan_memory.h"
#include "planner/oarp/oarp_planner.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

class PlanMemoryTest : public ::testing::Test {
 protected:
  PlanMemoryTest() : map_(testing::LoadShippedMap("sample_office.yaml")) {}

  MapSource Source(const std::string& id = "office") const {
    MapSource s;
    s.map_id = id;
    s.load = [this]() -> absl::StatusOr<SiteMap> {
      SiteMap site;
      site.raster = std::make_shared<const OccupancyMap>(map_);
      return site;
    };
    return s;
  }
  static PlanRequest Request() {
    PlanRequest r;
    r.common.robot.tool_width_m = 0.8;
    r.common.time_limit_s = 60;  // the default effort converges long before: deterministic
    r.common.seed = 3;
    return r;
  }
  EngineResult MustPlan(const PlanningEngine& engine, const PlanRequest& r,
                        const std::string& id = "office") {
    absl::StatusOr<EngineResult> result = engine.Plan(Source(id), r);
    EXPECT_TRUE(result.ok()) << result.status();
    return result.ok() ? *std::move(result) : EngineResult{};
  }
  static void ExpectSamePath(const CoveragePlan& a, const CoveragePlan& b) {
    ASSERT_EQ(a.path.size(), b.path.size());
    for (size_t i = 0; i < a.path.size(); ++i) {
      EXPECT_EQ(a.path[i].x, b.path[i].x) << i;
      EXPECT_EQ(a.path[i].y, b.path[i].y) << i;
      EXPECT_EQ(a.path[i].theta, b.path[i].theta) << i;
      EXPECT_EQ(a.path[i].kind, b.path[i].kind) << i;
    }
  }

  const PlannerRegistry registry_ = BuiltinPlanners();
  OccupancyMap map_;
};

TEST_F(PlanMemoryTest, IdenticalRequestIsACacheHitWithTheSamePath) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  const EngineResult first = MustPlan(engine, Request());
  EXPECT_EQ(first.plan.stats.plan_source, PlanOrigin::kCold);
  PlanRequest again = Request();
  again.common.time_limit_s = 5;  // the time budget is not part of the key
  const EngineResult hit = MustPlan(engine, again);
  EXPECT_EQ(hit.plan.stats.plan_source, PlanOrigin::kCacheHit);
  EXPECT_EQ(hit.plan.stats.tour_ms, 0.0);
  EXPECT_EQ(hit.plan.grid.get(), hit.area->drive.get());
  ExpectSamePath(first.plan, hit.plan);
  EXPECT_EQ(hit.plan.stats.estimated_duration_s, first.plan.stats.estimated_duration_s);
  EXPECT_EQ(testing::CheckPlanConformance(hit.plan, *hit.area, again.common.robot), "");
}

TEST_F(PlanMemoryTest, AnyOtherInputIsNotAHit) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  MustPlan(engine, Request());

  PlanRequest seed = Request();
  seed.common.seed = 4;  // a cold search would search another way: warm start, not a hit
  EXPECT_EQ(MustPlan(engine, seed).plan.stats.plan_source, PlanOrigin::kWarmStart);

  PlanRequest zones = Request();
  zones.no_go = {{{{2.1, 1.3}, {3.7, 1.6}, {3.2, 3.1}, {2.1, 1.3}}, {}}};
  EXPECT_EQ(MustPlan(engine, zones).plan.stats.plan_source, PlanOrigin::kCold);

  PlanRequest tool = Request();
  tool.common.robot.tool_width_m = 0.7;
  EXPECT_EQ(MustPlan(engine, tool).plan.stats.plan_source, PlanOrigin::kCold);

  PlanRequest robot = Request();
  robot.common.robot.turn_rate_deg_s = 45;
  EXPECT_EQ(MustPlan(engine, robot).plan.stats.plan_source, PlanOrigin::kCold);

  PlanRequest options = Request();
  auto thorough = std::make_shared<OarpOptions>();
  thorough->tour_effort = GtspEffort::kFast;
  options.options = thorough;
  EXPECT_EQ(MustPlan(engine, options).plan.stats.plan_source, PlanOrigin::kCold);

  PlanRequest threads = Request();
  threads.common.num_threads = 2;
  EXPECT_EQ(MustPlan(engine, threads).plan.stats.plan_source, PlanOrigin::kWarmStart);

  // Another map content id.
  EXPECT_EQ(MustPlan(engine, Request(), "office-v2").plan.stats.plan_source, PlanOrigin::kCold);
  // And the original is still remembered.
  EXPECT_EQ(MustPlan(engine, Request()).plan.stats.plan_source, PlanOrigin::kCacheHit);
}

TEST_F(PlanMemoryTest, NewStartPoseWarmStartsFromThereAndCoversEveryCell) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  const EngineResult cold = MustPlan(engine, Request());
  // Start poses on the path of the first plan (free, reachable cells).
  for (size_t k : {cold.plan.path.size() / 3, 2 * cold.plan.path.size() / 3}) {
    PlanRequest r = Request();
    const Waypoint& at = cold.plan.path[k];
    r.common.robot.start = Pose2{at.x, at.y, 1.0};
    const EngineResult warm = MustPlan(engine, r);
    SCOPED_TRACE(k);
    EXPECT_EQ(warm.plan.stats.plan_source, PlanOrigin::kWarmStart);
    ASSERT_FALSE(warm.plan.path.empty());
    EXPECT_DOUBLE_EQ(warm.plan.path.front().x, at.x);
    EXPECT_DOUBLE_EQ(warm.plan.path.front().y, at.y);
    // Back to the start (no end pose given).
    EXPECT_NEAR(warm.plan.path.back().x, at.x, 1e-9);
    EXPECT_NEAR(warm.plan.path.back().y, at.y, 1e-9);
    EXPECT_EQ(warm.plan.stats.covered_cells, warm.plan.stats.free_cells);
    EXPECT_EQ(testing::CheckPlanConformance(warm.plan, *warm.area, r.common.robot), "");
    // The same start pose again: now remembered.
    const EngineResult hit = MustPlan(engine, r);
    EXPECT_EQ(hit.plan.stats.plan_source, PlanOrigin::kCacheHit);
    ExpectSamePath(warm.plan, hit.plan);
  }
  // An end pose as well.
  PlanRequest r = Request();
  const Waypoint& end = cold.plan.path[cold.plan.path.size() / 2];
  r.common.robot.end = Pose2{end.x, end.y, 0.0};
  const EngineResult to_end = MustPlan(engine, r);
  EXPECT_EQ(to_end.plan.stats.plan_source, PlanOrigin::kWarmStart);
  EXPECT_NEAR(to_end.plan.path.back().x, end.x, 1e-9);
  EXPECT_NEAR(to_end.plan.path.back().y, end.y, 1e-9);
  EXPECT_EQ(testing::CheckPlanConformance(to_end.plan, *to_end.area, r.common.robot), "");
}

TEST_F(PlanMemoryTest, ColdPlansStayDeterministicForASeed) {
  LocalArtifactCache cache_a, cache_b, cache_off;
  PlanningEngine a(&registry_, &cache_a, EngineLimits{});
  PlanningEngine b(&registry_, &cache_b, EngineLimits{});
  EngineLimits off;
  off.plan_memory = false;
  PlanningEngine without(&registry_, &cache_off, off);
  const EngineResult ra = MustPlan(a, Request());
  const EngineResult rb = MustPlan(b, Request());
  const EngineResult r1 = MustPlan(without, Request());
  const EngineResult r2 = MustPlan(without, Request());
  for (const EngineResult* r : {&ra, &rb, &r1, &r2})
    EXPECT_EQ(r->plan.stats.plan_source, PlanOrigin::kCold);
  ExpectSamePath(ra.plan, rb.plan);
  ExpectSamePath(ra.plan, r1.plan);
  ExpectSamePath(ra.plan, r2.plan);
  EXPECT_EQ(cache_off.size(), 5u);  // artifacts only, nothing remembered
}

TEST_F(PlanMemoryTest, ImproveRememberedSearchesOnAndKeepsTheBetterPlan) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  PlanRequest quick = Request();
  auto fast = std::make_shared<OarpOptions>();
  fast->tour_effort = GtspEffort::kFast;
  quick.options = fast;
  const EngineResult first = MustPlan(engine, quick);
  PlanRequest more = quick;
  more.improve_remembered = true;
  const EngineResult improved = MustPlan(engine, more);
  EXPECT_EQ(improved.plan.stats.plan_source, PlanOrigin::kImproved);
  EXPECT_LE(improved.plan.stats.estimated_duration_s, first.plan.stats.estimated_duration_s);
  EXPECT_EQ(testing::CheckPlanConformance(improved.plan, *improved.area, more.common.robot), "");
  const EngineResult hit = MustPlan(engine, quick);
  EXPECT_EQ(hit.plan.stats.plan_source, PlanOrigin::kCacheHit);
  ExpectSamePath(improved.plan, hit.plan);
}

// The sparse tour search (large maps) starts from a remembered tour too: a
// new start pose re-cuts it and descends (warm_start) to a plan as good as a
// cold search from that pose within a few percent, and improve_remembered
// searches on from it with a new seed and keeps the better.
TEST_F(PlanMemoryTest, SparsePlansWarmStartFromTheRememberedTour) {
  LocalArtifactCache cache;
  EngineLimits limits;
  limits.dense_transition_bytes = 0;  // every map takes the sparse path
  PlanningEngine engine(&registry_, &cache, limits);
  const PlanRequest r = Request();
  const EngineResult first = MustPlan(engine, r);
  ASSERT_EQ(first.plan.stats.tour_solver, "sparse");
  EXPECT_EQ(first.plan.stats.plan_source, PlanOrigin::kCold);
  EXPECT_EQ(first.plan.tour_vertices.size(), first.plan.stats.num_ranks);
  const EngineResult hit = MustPlan(engine, r);
  EXPECT_EQ(hit.plan.stats.plan_source, PlanOrigin::kCacheHit);
  ExpectSamePath(first.plan, hit.plan);

  PlanRequest moved = r;
  moved.common.robot.start = Pose2{first.plan.path.back().x, first.plan.path.back().y, 0.0};
  const EngineResult warm = MustPlan(engine, moved);
  EXPECT_EQ(warm.plan.stats.plan_source, PlanOrigin::kWarmStart);
  EXPECT_EQ(testing::CheckPlanConformance(warm.plan, *warm.area, moved.common.robot), "");
  EXPECT_EQ(warm.plan.stats.num_ranks, first.plan.stats.num_ranks);
  LocalArtifactCache fresh_cache;
  PlanningEngine fresh(&registry_, &fresh_cache, limits);
  const EngineResult cold = MustPlan(fresh, moved);
  EXPECT_EQ(cold.plan.stats.plan_source, PlanOrigin::kCold);
  EXPECT_LE(warm.plan.stats.estimated_duration_s, 1.05 * cold.plan.stats.estimated_duration_s);

  PlanRequest more = r;
  more.improve_remembered = true;
  const EngineResult improved = MustPlan(engine, more);
  EXPECT_EQ(improved.plan.stats.plan_source, PlanOrigin::kImproved);
  EXPECT_LE(improved.plan.stats.estimated_duration_s, first.plan.stats.estimated_duration_s);
  EXPECT_EQ(testing::CheckPlanConformance(improved.plan, *improved.area, more.common.robot), "");
}

// A search its own time limit stopped answers requests with no more time;
// one with more searches on from it.
TEST_F(PlanMemoryTest, TimeLimitedPlanAnswersNoLongerBudgetAndImprovesWithMore) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  PlanRequest r = Request();
  auto thorough = std::make_shared<OarpOptions>();
  thorough->tour_effort = GtspEffort::kThorough;  // searches until the time limit
  r.options = thorough;
  r.common.time_limit_s = 0.2;
  const EngineResult timed = MustPlan(engine, r);
  ASSERT_EQ(timed.plan.termination.limit, TerminationLimit::kTime);
  const auto recalled = [&] {
    absl::StatusOr<std::optional<Recalled>> found = engine.Recall(Source(), r);
    EXPECT_TRUE(found.ok()) << found.status();
    return found.ok() && found->has_value();
  };
  r.common.time_limit_s = 0.1;
  EXPECT_TRUE(recalled());
  EXPECT_EQ(MustPlan(engine, r).plan.stats.plan_source, PlanOrigin::kCacheHit);
  r.common.time_limit_s = 0.4;
  EXPECT_FALSE(recalled());  // more time than it was searched for: Plan searches on
  const EngineResult more = MustPlan(engine, r);
  EXPECT_EQ(more.plan.stats.plan_source, PlanOrigin::kImproved);
  EXPECT_LE(more.plan.stats.estimated_duration_s, timed.plan.stats.estimated_duration_s);
  // Now remembered for 0.4 s.
  const EngineResult hit = MustPlan(engine, r);
  EXPECT_EQ(hit.plan.stats.plan_source, PlanOrigin::kCacheHit);
  ExpectSamePath(more.plan, hit.plan);
}

// Recall finds what Plan would answer at once, and nothing else, without
// loading the map or building anything.
TEST_F(PlanMemoryTest, RecallFindsExactlyWhatPlanAnswersAtOnce) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  int loads = 0;
  MapSource counted = Source();
  counted.load = [&, load = counted.load] {
    ++loads;
    return load();
  };

  absl::StatusOr<std::optional<Recalled>> none = engine.Recall(counted, Request());
  ASSERT_TRUE(none.ok()) << none.status();
  EXPECT_FALSE(none->has_value());
  EXPECT_EQ(loads, 0);
  // Nothing was built: the first plan still builds the grid.
  absl::StatusOr<EngineResult> cold = engine.Plan(counted, Request());
  ASSERT_TRUE(cold.ok()) << cold.status();
  EXPECT_EQ(loads, 1);
  EXPECT_FALSE(cold->plan.stats.decomposition_cached);

  PlanRequest again = Request();
  again.common.time_limit_s = 5;
  absl::StatusOr<std::optional<Recalled>> recalled = engine.Recall(counted, again);
  ASSERT_TRUE(recalled.ok()) << recalled.status();
  ASSERT_TRUE(recalled->has_value());
  const Recalled& r = **recalled;
  ExpectSamePath(cold->plan, r.entry->plan);
  EXPECT_EQ(r.area.get(), cold->area.get());
  EXPECT_GE(r.lookup_ms, 0.0);
  const EngineResult hit = MustPlan(engine, again);
  EXPECT_EQ(hit.plan.stats.plan_source, PlanOrigin::kCacheHit);
  EXPECT_EQ(hit.answered_by.get(), r.entry.get());
  EXPECT_EQ(loads, 1);

  // What Plan would search for is not recalled.
  PlanRequest improve = Request();
  improve.improve_remembered = true;
  PlanRequest seed = Request();
  seed.common.seed = 4;
  PlanRequest tool = Request();
  tool.common.robot.tool_width_m = 0.7;  // another grid, not cached
  for (const PlanRequest& other : {improve, seed, tool}) {
    absl::StatusOr<std::optional<Recalled>> miss = engine.Recall(counted, other);
    ASSERT_TRUE(miss.ok()) << miss.status();
    EXPECT_FALSE(miss->has_value());
  }
  EXPECT_EQ(loads, 1);
  // Bad input is refused as Plan refuses it.
  PlanRequest bad = Request();
  bad.common.time_limit_s = -1;
  EXPECT_EQ(engine.Recall(counted, bad).status().code(), absl::StatusCode::kInvalidArgument);
  bad = Request();
  bad.regions = {{{{100, 100}, {101, 100}, {101, 101}, {100, 100}}, {}}};  // outside the map
  EXPECT_EQ(engine.Recall(counted, bad).status().code(), absl::StatusCode::kInvalidArgument);

  // Without plan memory nothing is recalled.
  EngineLimits forgetful;
  forgetful.plan_memory = false;
  PlanningEngine without(&registry_, &cache, forgetful);
  absl::StatusOr<std::optional<Recalled>> off = without.Recall(counted, Request());
  ASSERT_TRUE(off.ok()) << off.status();
  EXPECT_FALSE(off->has_value());
}

TEST_F(PlanMemoryTest, BadInputIsStillInvalidArgumentWhenAPlanIsRemembered) {
  LocalArtifactCache cache;
  PlanningEngine engine(&registry_, &cache, EngineLimits{});
  MustPlan(engine, Request());
  PlanRequest bad = Request();
  bad.common.time_limit_s = -1;
  EXPECT_EQ(engine.Plan(Source(), bad).status().code(), absl::StatusCode::kInvalidArgument);
  bad = Request();
  bad.common.robot.start = Pose2{-50, -50, 0};  // off the map
  EXPECT_EQ(engine.Plan(Source(), bad).status().code(), absl::StatusCode::kInvalidArgument);
  bad = Request();
  bad.regions = {{{{100, 100}, {101, 100}, {101, 101}, {100, 100}}, {}}};  // outside the map
  EXPECT_EQ(engine.Plan(Source(), bad).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace covplan
