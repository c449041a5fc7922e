// Checks of a plan as the service returns it, shared by the server tests.
//
//   ExpectArrivalTimes(reply.plan());
#ifndef COVPLAN_TESTS_SERVER_PLAN_CHECKS_H_
#define COVPLAN_TESTS_SERVER_PLAN_CHECKS_H_

#include <algorithm>

#include "covplan/v1/covplan.pb.h"
#include "gtest/gtest.h"

namespace covplan::testing {

// Every waypoint has its arrival time: 0 at the start, never decreasing,
// and the last one the plan's estimated duration (a plan without recharge
// stops).
inline void ExpectArrivalTimes(const v1::PlanResponse& plan) {
  ASSERT_GT(plan.path_size(), 0);
  EXPECT_EQ(plan.path(0).time_s(), 0.0);
  for (int i = 1; i < plan.path_size(); ++i) {
    ASSERT_GE(plan.path(i).time_s(), plan.path(i - 1).time_s()) << "waypoint " << i;
  }
  const double duration = plan.stats().estimated_duration_s();
  EXPECT_NEAR(plan.path(plan.path_size() - 1).time_s(), duration, 1e-6 * std::max(1.0, duration));
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_PLAN_CHECKS_H_
