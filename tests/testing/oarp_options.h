// OARP's options for tests that plan through PlanCoverage (PlanOptions::
// options), e.g. the greedy tour where the tour is not what is tested.
//
//   PlanOptions o; o.options = testing::OarpOptionsWith(TourSolver::kGreedy);
//
// Thread-safety: a pure function.
#ifndef COVPLAN_TESTS_TESTING_OARP_OPTIONS_H_
#define COVPLAN_TESTS_TESTING_OARP_OPTIONS_H_

#include <memory>

#include "planner/oarp/oarp_planner.h"

namespace covplan::testing {

inline std::shared_ptr<const OarpOptions> OarpOptionsWith(
    TourSolver tour, PartitionSolver partition = PartitionSolver::kPushRelabel) {
  auto options = std::make_shared<OarpOptions>();
  options->tour_solver = tour;
  options->partition_solver = partition;
  return options;
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_OARP_OPTIONS_H_
