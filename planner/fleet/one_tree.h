// The Held-Karp bound (1-trees with Lagrangian node penalties, improved by
// subgradient steps) on the cheapest Hamiltonian cycle that contains a
// given perfect matching of forced edges. The fleet's lower bound uses it
// over the unit ends and the robots' poses: a unit's two ends are joined by
// the unit itself, robot r's end by a free link to robot r + 1's start, so
// the k robots' paths chained in turn are such a cycle (docs/fleet.md).
//
// Any penalties give a valid bound (Held and Karp, 1970): for a cycle C,
// cost(C) = sum over C of (c_ij + p_i + p_j) - 2 sum p, and C less one
// vertex's two edges is a spanning tree of the rest that holds every forced
// edge not at that vertex. So the least such "1-tree" under the penalised
// costs, less 2 sum p, is at most the cheapest cycle. The subgradient steps
// only choose good penalties.
//
//   std::vector<double> c(n * n);     // symmetric; +inf: no edge
//   std::vector<int> partner(n);      // the forced matching
//   std::optional<double> lb = HeldKarpBound(c, partner, 100'000'000);
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_FLEET_ONE_TREE_H_
#define COVPLAN_PLANNER_FLEET_ONE_TREE_H_

#include <cstdint>
#include <optional>
#include <vector>

namespace covplan {

// `costs`: row-major symmetric n x n (the forced edges' costs included,
// +inf: no edge); `partner[i]`: the vertex i's forced edge joins, a perfect
// matching (partner[partner[i]] == i != partner[i]). `work_budget` bounds
// the vertex-pair visits (about n^2 per subgradient step). nullopt when
// n < 4 or no cycle through the forced edges can exist (a vertex without a
// free edge, or a graph the free edges leave disconnected).
std::optional<double> HeldKarpBound(const std::vector<double>& costs,
                                    const std::vector<int>& partner, int64_t work_budget);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_ONE_TREE_H_
