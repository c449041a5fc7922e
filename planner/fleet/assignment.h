// Two classic relaxations' solvers for the fleet's lower bound.
//
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

// The minimum-cost perfect matching of a complete graph on n vertices
// (symmetric row-major n x n costs, +inf: no edge), by Boost.Graph's
// maximum_weighted_matching (Edmonds' blossoms) on integer weights
// C - cost (costs in microseconds, rounded down, so the result is never
// above the true minimum; C large enough that every maximum-weight
// matching is perfect). nullopt when no perfect matching exists.
std::optional<double> MinPerfectMatchingCost(const std::vector<double>& costs, int n);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_ASSIGNMENT_H_
