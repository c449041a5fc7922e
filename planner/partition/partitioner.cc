#include "planner/partition/partitioner.h"

#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/partition/push_relabel_partitioner.h"

namespace covplan {

std::unique_ptr<RankPartitioner> MakePartitioner(PartitionSolver solver) {
  switch (solver) {
    case PartitionSolver::kLp: return std::make_unique<LpPartitioner>();
    case PartitionSolver::kMatching: return std::make_unique<MatchingPartitioner>();
    case PartitionSolver::kPushRelabel: return std::make_unique<PushRelabelPartitioner>();
    case PartitionSolver::kMinCut: break;
  }
  return std::make_unique<MinCutPartitioner>();
}

}  // namespace covplan
