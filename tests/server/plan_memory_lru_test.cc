// Remembered plans in the server's bounded cache: Put replaces an entry and
// releases its bytes, Find refreshes it; a remembered plan is accounted
// against the one byte budget (at least its plan's MemoryBytes), and
// planning other requests within a tight budget evicts it (the request is
// then no longer a hit).
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"
#include "server/artifact_lru.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

struct Blob {
  size_t bytes = 0;
  int id = 0;
};

TEST(SharedLruCachePutTest, PutReplacesFindRefreshesAndTheBudgetHolds) {
  SharedLruCache<Blob> cache(100, [](const Blob& b) { return b.bytes; });
  cache.Put("a", std::make_shared<const Blob>(Blob{40, 1}));
  cache.Put("b", std::make_shared<const Blob>(Blob{40, 2}));
  EXPECT_EQ(cache.stats().bytes, 80u);
  cache.Put("a", std::make_shared<const Blob>(Blob{30, 3}));  // replaced: 40 bytes released
  EXPECT_EQ(cache.stats().bytes, 70u);
  EXPECT_EQ(cache.stats().entries, 2u);
  ASSERT_NE(cache.Find("a"), nullptr);
  EXPECT_EQ(cache.Find("a")->id, 3);
  EXPECT_EQ(cache.Find("b")->id, 2);                          // b is now the most recently used
  cache.Put("c", std::make_shared<const Blob>(Blob{50, 4}));  // evicts a (least recently used)
  EXPECT_EQ(cache.Find("a"), nullptr);
  EXPECT_NE(cache.Find("b"), nullptr);
  EXPECT_NE(cache.Find("c"), nullptr);
  EXPECT_EQ(cache.stats().bytes, 90u);
  EXPECT_EQ(cache.stats().evictions, 1);
  cache.Put("b", std::make_shared<const Blob>(Blob{200, 5}));  // larger than the budget: dropped
  EXPECT_EQ(cache.Find("b"), nullptr);
  EXPECT_EQ(cache.stats().bytes, 50u);
  EXPECT_EQ(cache.stats().entries, 1u);
  cache.EraseWithPrefix("c");
  EXPECT_EQ(cache.Find("c"), nullptr);
  EXPECT_EQ(cache.stats().bytes, 0u);
}

MapSource Office(const OccupancyMap* map) {
  MapSource s;
  s.map_id = "office";
  s.load = [map]() -> absl::StatusOr<SiteMap> {
    SiteMap site;
    site.raster = std::make_shared<const OccupancyMap>(*map);
    return site;
  };
  return s;
}

PlanRequest Request(uint64_t seed) {
  PlanRequest r;
  r.common.robot.tool_width_m = 0.8;
  r.common.time_limit_s = 60;
  r.common.seed = seed;
  return r;
}

TEST(PlanMemoryBudgetTest, RememberedPlansAreAccountedAndEvicted) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  const MapSource source = Office(&map);

  // How much the artifacts take, and how much one remembered plan adds.
  ArtifactLru roomy(256 << 20);
  PlanningEngine probe(&registry, &roomy, EngineLimits{});
  ASSERT_TRUE(probe.Prepare(source, Request(1)).ok());
  const size_t artifacts = roomy.stats().bytes;
  absl::StatusOr<EngineResult> first = probe.Plan(source, Request(1));
  ASSERT_TRUE(first.ok()) << first.status();
  const size_t with_plan = roomy.stats().bytes;
  EXPECT_EQ(roomy.stats().entries, 7u);  // 5 artifacts + remembered tour + plan
  // The remembered copy (its vectors without the returned plan's slack).
  const CoveragePlan copy = first->plan;
  EXPECT_GE(with_plan - artifacts, copy.MemoryBytes());

  // A budget with room for exactly that: a second remembered plan (another
  // seed) evicts the least recently used entry, the first request's plan.
  ArtifactLru tight(with_plan);
  PlanningEngine engine(&registry, &tight, EngineLimits{});
  absl::StatusOr<EngineResult> a = engine.Plan(source, Request(1));
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->plan.stats.plan_source, PlanOrigin::kCold);
  absl::StatusOr<EngineResult> again = engine.Plan(source, Request(1));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->plan.stats.plan_source, PlanOrigin::kCacheHit);
  absl::StatusOr<EngineResult> other = engine.Plan(source, Request(2));
  ASSERT_TRUE(other.ok());
  EXPECT_EQ(other->plan.stats.plan_source, PlanOrigin::kWarmStart);
  EXPECT_LE(tight.stats().bytes, tight.budget_bytes());
  EXPECT_GE(tight.stats().evictions, 1);
  absl::StatusOr<EngineResult> evicted = engine.Plan(source, Request(1));
  ASSERT_TRUE(evicted.ok());
  EXPECT_NE(evicted->plan.stats.plan_source, PlanOrigin::kCacheHit);
}

// Identical requests planned at once on several threads: every one gets a
// whole plan (cold or remembered), all are the same plan (the seed fixes a
// converged search), and the one remembered afterwards is that plan.
TEST(PlanMemoryBudgetTest, ConcurrentIdenticalRequestsShareOneAnswer) {
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  const PlannerRegistry registry = BuiltinPlanners();
  const MapSource source = Office(&map);
  ArtifactLru cache(256 << 20);
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  constexpr int kThreads = 4;
  std::vector<absl::StatusOr<EngineResult>> results(kThreads, absl::UnknownError("not run"));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] { results[t] = engine.Plan(source, Request(5)); });
  }
  for (std::thread& t : threads) t.join();
  absl::StatusOr<EngineResult> after = engine.Plan(source, Request(5));
  ASSERT_TRUE(after.ok()) << after.status();
  EXPECT_EQ(after->plan.stats.plan_source, PlanOrigin::kCacheHit);
  for (const absl::StatusOr<EngineResult>& r : results) {
    ASSERT_TRUE(r.ok()) << r.status();
    const PlanOrigin source_of = r->plan.stats.plan_source;
    EXPECT_TRUE(source_of == PlanOrigin::kCold || source_of == PlanOrigin::kCacheHit);
    ASSERT_EQ(r->plan.path.size(), after->plan.path.size());
    for (size_t i = 0; i < r->plan.path.size(); ++i) {
      EXPECT_EQ(r->plan.path[i].x, after->plan.path[i].x);
      EXPECT_EQ(r->plan.path[i].y, after->plan.path[i].y);
    }
    EXPECT_EQ(r->plan.stats.covered_cells, r->plan.stats.free_cells);
  }
}

}  // namespace
}  // namespace covplan
