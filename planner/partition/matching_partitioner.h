// Exact minimum rank partition as a maximum bipartite matching.
//
// A rank of k cells has k - 1 internal adjacencies, so ranks = free cells -
// the adjacencies whose two cells share the adjacency's orientation. Keeping a
// horizontal adjacency (both cells H) forbids every vertical adjacency (both
// cells V) that shares a cell with it, and nothing else: the most adjacencies
// kept is a maximum independent set of the bipartite conflict graph
// "H-adjacencies against V-adjacencies sharing a cell". By König,
// |MIS| = |H| + |V| - |maximum matching|, and the complement of the minimum
// vertex cover built from the matching is such a set; its adjacencies give
// every cell its orientation. Adjacencies are Passable() links, so thin-wall
// barriers and blocked cells are honoured exactly as by the min-cut.
//
// The conflict graph is implicit in the grid (an H-adjacency meets at most
// four V-adjacencies), so nothing but a few per-cell arrays is allocated.
// A greedy initial matching, then multi-source BFS phases (default) or
// Hopcroft-Karp; see docs/benchmarks-archive.md §1b for why the default.
//
//   MatchingPartitioner p;
//   absl::StatusOr<RankPartition> part = p.Partition(grid, stop);
//
// Thread-safety: stateless; Partition() is reentrant.
#ifndef COVPLAN_PLANNER_PARTITION_MATCHING_PARTITIONER_H_
#define COVPLAN_PLANNER_PARTITION_MATCHING_PARTITIONER_H_

#include "planner/partition/partitioner.h"

namespace covplan {

enum class MatchingAlgorithm {
  kMultiSourceBfs,  // BFS forest of alternating trees with tree grafting (Azad et al.)
  kHopcroftKarp,    // per phase, vertex-disjoint shortest augmenting paths
  kPothenFan,       // per phase, one depth-first search per free node, with lookahead (PF+)
};

class MatchingPartitioner final : public RankPartitioner {
 public:
  // `greedy_start`: match greedily first (off only to measure it).
  explicit MatchingPartitioner(MatchingAlgorithm algorithm = MatchingAlgorithm::kMultiSourceBfs,
                               bool greedy_start = true)
      : algorithm_(algorithm), greedy_start_(greedy_start) {}
  std::string_view name() const override { return "matching"; }
  // Polls `stop` between and during the phases: DeadlineExceeded.
  absl::StatusOr<RankPartition> Partition(const Grid& grid, const StopToken& stop) const override;

 private:
  MatchingAlgorithm algorithm_;
  bool greedy_start_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_MATCHING_PARTITIONER_H_
