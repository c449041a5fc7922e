// Minimum rank partition (OARP, thesis ch. 3): orient every free cell H or V
// so that the number of ranks is minimal. Four exact solvers share this
// interface: the s-t minimum cut (by push-relabel on the grid, the default,
// or by Boost's Boykov-Kolmogorov), a maximum bipartite matching on the
// conflict graph (König), and the thesis's GLPK LP (reference). All return
// an optimal partition; ties may differ.
//
//   std::unique_ptr<RankPartitioner> p = MakePartitioner(PartitionSolver::kPushRelabel);
//   absl::StatusOr<RankPartition> part = p->Partition(grid, StopToken());
//
// Thread-safety: implementations are stateless; Partition() is reentrant.
#ifndef COVPLAN_PLANNER_PARTITION_PARTITIONER_H_
#define COVPLAN_PLANNER_PARTITION_PARTITIONER_H_

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"

namespace covplan {

enum class PartitionSolver { kMinCut, kLp, kMatching, kPushRelabel };

class RankPartitioner {
 public:
  virtual ~RankPartitioner() = default;
  virtual std::string_view name() const = 0;
  // InvalidArgument on an empty grid; DeadlineExceeded/Cancelled if `stop`
  // fires (the LP gets the remaining time as its GLPK time limit).
  virtual absl::StatusOr<RankPartition> Partition(const Grid& grid,
                                                  const StopToken& stop) const = 0;
};

std::unique_ptr<RankPartitioner> MakePartitioner(PartitionSolver solver);

// The ranks of an exact solver's `orientation`, checked against the optimum
// the solver proved: Internal, naming `solver`, if their counts differ.
absl::StatusOr<RankPartition> CheckedPartition(const Grid& grid, std::vector<uint8_t> orientation,
                                               int64_t optimum, std::string_view solver);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_PARTITIONER_H_
