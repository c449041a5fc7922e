// Exact minimum rank partition as an s-t minimum cut (algorithms.md §2).
//
// The thesis LP has only submodular pairwise terms a*(1-b), so its optimum is
// a minimum cut: one node per free cell, source side = horizontal. Solved with
// Boost.Graph's Boykov-Kolmogorov max-flow on a compressed sparse row graph.
//
// Thread-safety: stateless; Partition() is reentrant.
#ifndef COVPLAN_PLANNER_PARTITION_MINCUT_PARTITIONER_H_
#define COVPLAN_PLANNER_PARTITION_MINCUT_PARTITIONER_H_

#include "planner/partition/partitioner.h"

namespace covplan {

class MinCutPartitioner final : public RankPartitioner {
 public:
  // `greedy_preflow`: push a blocking flow along the monotone paths of the
  // cut graph (a DAG) before Boykov-Kolmogorov runs on the residual graph.
  explicit MinCutPartitioner(bool greedy_preflow = true) : greedy_preflow_(greedy_preflow) {}
  std::string_view name() const override { return "mincut"; }
  absl::StatusOr<RankPartition> Partition(const Grid& grid, const StopToken& stop) const override;

 private:
  bool greedy_preflow_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_MINCUT_PARTITIONER_H_
