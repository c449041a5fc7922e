// Two classic relaxations for the fleet's lower bound.
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

// A lower bound on the minimum-cost perfect matching of a complete graph on
// n vertices (symmetric row-major n x n costs, +inf: no edge): half the
// minimum-cost assignment with the diagonal forbidden. A perfect matching
// read both ways is such an assignment of twice its cost. Bounded O(n^3)
// (Boost.Graph's weighted matching in Debian's Boost 1.74 can loop forever
// on some inputs, so it is not used). nullopt when no assignment exists.
std::optional<double> PerfectMatchingLowerBound(const std::vector<double>& costs, int n);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_ASSIGNMENT_H_
