// Exact minimum rank partition as an s-t minimum cut, solved by FIFO
// push-relabel with global relabelling on the grid itself.
//
// The cut graph. Write x_c = 1 when cell c is horizontal (H). The ranks of
// an orientation are the free cells minus the links kept: a +col link a-b
// is kept when both cells are H, a +row link when both are V. Per link,
//   -[a H][b H]  = -[b H] + [a V][b H]    (+col link a -> b)
//   -[a V][b V]  = -[a V] + [a V][b H]    (+row link a -> b)
// so ranks = constant + sum of unary terms + sum over links of [a V][b H],
// where constant = free cells - col links - row links + the cells linked in
// both -col and +row, and a cell's unary terms cancel unless it is linked in
// exactly one of them: [c H] if only in +row (an arc s -> c), [c V] if only
// in -col (an arc c -> t). [a V][b H] is an arc a -> b, cut when a is on the
// source side (V) and b on the sink side (H). Every arc has capacity 1 and
// runs towards +col or +row: a planar DAG laid on the grid. (MinCutPartitioner
// writes the same minimum with the opposite pair term, [a H][b V], for Boost;
// algorithms.md §2 derives that one.)
//
// Interior cells have no terminal arc, so the flow, a few units per blocked
// cell, must cross open ground to reach a sink: on an open field augmenting
// paths are hundreds to thousands of cells long, which is what makes
// Boykov-Kolmogorov and the matching's augmenting searches slow there
// (docs/benchmarks.md §1). Push-relabel moves all excess at once along
// exact distance labels, recomputed by one breadth-first search from the
// sinks every n / 24 relabels.
//
// Memory: the arcs and their flow live in bit flags, one byte per cell, plus
// the excess (1 byte), the label (4 bytes) and at most 8 bytes of queues per
// cell. The answer is checked before it is returned: the flow is audited
// (capacities, conservation, the units that reached t), and the ranks
// counted from the cut must equal the constant plus that flow (weak
// duality); else Internal.
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

namespace push_relabel_internal {

// Test seam for the flow audit: one kind of damage to a maximum preflow.
enum class FlowDamage {
  kNone,
  kFlowOnMissingArc,  // a cell sends a unit across a side it has no link on
  kUnitLost,          // a unit vanishes from an arc that carried it
  kExtraUnitToT,      // an unused sink drains a unit it never received
};
// Runs phase one on `grid`, applies `damage` at the first cell it applies
// to and returns the audit's verdict: Internal naming what is wrong, or OK
// for kNone. FailedPrecondition when the grid offers no place for it.
absl::Status AuditDamagedFlow(const Grid& grid, FlowDamage damage);

}  // namespace push_relabel_internal
}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_PUSH_RELABEL_PARTITIONER_H_
