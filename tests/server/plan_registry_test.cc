// PlanRegistry: plans by id, bounded by age and count, and aliases (a
// second id for a plan's content) that are copied under their own id when
// first looked up, name their original by id once it is gone, and never
// push plans out.
#include "server/plan_registry.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"

namespace covplan {
namespace {

std::shared_ptr<const RetainedPlan> Retained(const std::string& id, int waypoints) {
  auto plan = std::make_shared<RetainedPlan>();
  plan->plan_id = id;
  plan->map_id = "m-1";
  plan->plan.path.resize(waypoints);
  return plan;
}

using Pairs = std::vector<std::pair<std::string, std::string>>;

TEST(PlanRegistry, AnAliasIsTheOriginalsContentUnderItsOwnId) {
  const absl::Time t0 = absl::FromUnixSeconds(1000);
  PlanRegistry plans(absl::Minutes(10), /*max_plans=*/4);
  const std::shared_ptr<const RetainedPlan> original = Retained("p-a", 7);
  plans.Put(original, t0);
  plans.PutAlias("p-b", "p-a", t0);
  plans.PutAlias("p-c", "p-a", t0);
  EXPECT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans.aliases(), 2u);
  EXPECT_EQ(plans.UnusedAliases(t0), (Pairs{{"p-b", "p-a"}, {"p-c", "p-a"}}));
  std::string made_from;
  std::shared_ptr<const RetainedPlan> b = plans.Get("p-b", t0, &made_from);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(made_from, "p-a");
  EXPECT_NE(b.get(), original.get());  // a copy, not the original
  EXPECT_EQ(b->plan_id, "p-b");
  EXPECT_EQ(b->map_id, "m-1");
  EXPECT_EQ(b->plan.path.size(), 7u);
  EXPECT_EQ(plans.Get("p-b", t0, &made_from), b);  // copied once, then retained
  EXPECT_EQ(made_from, "");
  EXPECT_EQ(plans.Get("p-a", t0), original);
  EXPECT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans.UnusedAliases(t0), (Pairs{{"p-c", "p-a"}}));
  EXPECT_EQ(plans.OriginalOf("p-b", t0), "p-a");
  EXPECT_EQ(plans.OriginalOf("p-a", t0), std::nullopt);
  plans.MarkUsed("p-c");
  EXPECT_TRUE(plans.UnusedAliases(t0).empty());
  // An id in use is not made an alias.
  plans.PutAlias("p-a", "p-z", t0);
  EXPECT_EQ(plans.Get("p-a", t0), original);
}

TEST(PlanRegistry, AnAliasWhoseOriginalIsGoneNamesItUntilItsOwnTtl) {
  const absl::Time t0 = absl::FromUnixSeconds(1000);
  PlanRegistry plans(absl::Minutes(10), /*max_plans=*/4);
  plans.Put(Retained("p-a", 3), t0);
  plans.PutAlias("p-b", "p-a", t0 + absl::Minutes(8));
  const absl::Time t1 = t0 + absl::Minutes(11);
  EXPECT_EQ(plans.Get("p-a", t1), nullptr);
  EXPECT_EQ(plans.Get("p-b", t1), nullptr);       // no copy: the original is gone
  EXPECT_EQ(plans.OriginalOf("p-b", t1), "p-a");  // the caller rebuilds it
  EXPECT_EQ(plans.OriginalOf("p-b", t0 + absl::Minutes(18)), std::nullopt);
  EXPECT_EQ(plans.aliases(), 0u);
}

TEST(PlanRegistry, AliasesAreBoundedApartAndNeverPushPlansOut) {
  const absl::Time t0 = absl::FromUnixSeconds(1000);
  PlanRegistry plans(absl::Minutes(10), /*max_plans=*/2);
  plans.Put(Retained("p-a", 1), t0);
  plans.Put(Retained("p-b", 1), t0);
  for (int i = 0; i < 200; ++i) plans.PutAlias("p-x" + std::to_string(i), "p-a", t0);
  // 64 aliases per retained plan: the oldest aliases went, no plan did.
  EXPECT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans.aliases(), 128u);
  EXPECT_NE(plans.Get("p-a", t0), nullptr);
  EXPECT_NE(plans.Get("p-b", t0), nullptr);
  EXPECT_EQ(plans.OriginalOf("p-x71", t0), std::nullopt);
  EXPECT_EQ(plans.OriginalOf("p-x72", t0), "p-a");
  // Using an alias retains its copy as a plan, which does count.
  EXPECT_NE(plans.Get("p-x199", t0), nullptr);
  EXPECT_EQ(plans.size(), 2u);
  EXPECT_EQ(plans.Get("p-a", t0), nullptr);  // the oldest plan made room
}

}  // namespace
}  // namespace covplan
