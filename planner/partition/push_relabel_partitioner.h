// Exact minimum rank partition as the s-t minimum cut of algorithms.md §2,
// solved by FIFO push-relabel with global relabelling on the grid itself.
//
// The cut graph of the partition is a planar DAG laid on the grid: every
// arc joins a cell to its neighbour in +col or +row, each with capacity 1;
// a cell linked in +row but not in -col is fed by the source, a cell linked
// in -col but not in +row drains to the sink (mirror images of the arcs
// MinCutPartitioner builds for Boost). Interior cells have no terminal arc,
// so the flow, a few units per blocked cell, must cross open ground to reach
// a sink: on an open field augmenting paths are hundreds to thousands of
// cells long, which is what makes Boykov-Kolmogorov and the matching's
// augmenting searches slow there (docs/benchmarks.md §1). Push-relabel moves
// all excess at once along exact distance labels, recomputed by one
// breadth-first search from the sinks every so often.
//
// Nothing is built but a byte of state and a distance label per cell: the
// arcs and their flow live in bit flags. The answer is checked before it is
// returned: the ranks counted from the cut must equal the constant plus the
// flow that reached the sink (weak duality), else Internal.
//
//   PushRelabelPartitioner p;
//   absl::StatusOr<RankPartition> part = p.Partition(grid, stop);
//
// Thread-safety: stateless; Partition() is reentrant.
#ifndef COVPLAN_PLANNER_PARTITION_PUSH_RELABEL_PARTITIONER_H_
#define COVPLAN_PLANNER_PARTITION_PUSH_RELABEL_PARTITIONER_H_

#include "planner/partition/partitioner.h"

namespace covplan {

class PushRelabelPartitioner final : public RankPartitioner {
 public:
  std::string_view name() const override { return "pushrelabel"; }
  // Polls `stop` during the pushes and the global relabellings: DeadlineExceeded.
  absl::StatusOr<RankPartition> Partition(const Grid& grid, const StopToken& stop) const override;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_PUSH_RELABEL_PARTITIONER_H_
