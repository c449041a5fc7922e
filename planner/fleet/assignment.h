// The minimum-cost assignment (linear assignment problem) of a dense square
// cost matrix: each row to a distinct column, minimising the summed cost.
// Kuhn-Munkres with potentials, one shortest augmenting path per row
// (O(n^3)), as in Jonker and Volgenant. Costs of +inf mark forbidden pairs.
//
//   std::optional<double> v = MinAssignmentCost(costs, n);  // nullopt: infeasible
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_FLEET_ASSIGNMENT_H_
#define COVPLAN_PLANNER_FLEET_ASSIGNMENT_H_

#include <optional>
#include <vector>

namespace covplan {

// `costs` is row-major n x n. nullopt when no assignment avoids +inf.
std::optional<double> MinAssignmentCost(const std::vector<double>& costs, int n);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_ASSIGNMENT_H_
