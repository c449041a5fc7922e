#include "planner/partition/partitioner.h"

#include <utility>

#include "absl/strings/str_format.h"

#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/partition/push_relabel_partitioner.h"

namespace covplan {

std::unique_ptr<RankPartitioner> MakePartitioner(PartitionSolver solver) {
  switch (solver) {
    case PartitionSolver::kLp:
      return std::make_unique<LpPartitioner>();
    case PartitionSolver::kMatching:
      return std::make_unique<MatchingPartitioner>();
    case PartitionSolver::kPushRelabel:
      return std::make_unique<PushRelabelPartitioner>();
    case PartitionSolver::kMinCut:
      break;
  }
  return std::make_unique<MinCutPartitioner>();
}

absl::StatusOr<RankPartition> CheckedPartition(const Grid& grid, std::vector<uint8_t> orientation,
                                               int64_t optimum, std::string_view solver) {
  RankPartition result;
  result.orientation = std::move(orientation);
  result.ranks = RanksFromOrientation(grid, result.orientation);
  result.objective = static_cast<double>(optimum);
  if (static_cast<int64_t>(result.ranks.size()) != optimum) {
    return absl::InternalError(
        absl::StrFormat("%s: optimum %d disagrees with the %d ranks of its orientation", solver,
                        optimum, result.ranks.size()));
  }
  return result;
}

}  // namespace covplan
