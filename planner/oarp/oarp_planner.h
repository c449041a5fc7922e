// OARP (Ramesh et al.): the minimum number of axis-parallel coverage lines
// ("ranks") over the cells to cover, ordered by an anytime GTSP whose costs
// are drive times over the drive grid. Registered as "oarp".
//
// Per-map artifacts, derived from the request's CoverageArea key:
//   ...|partition(<solver>)      the minimum rank partition of the cover grid
//   ...|partition(...)|transitions   any-angle paths between rank endpoints
//   ...|partition(...)|candidates    sparse nearest-endpoint graph (large maps)
//
//   OarpOptions opts; opts.tour_solver = TourSolver::kGreedy;
//   request.planner = "oarp"; request.options = std::make_shared<OarpOptions>(opts);
//
// Thread-safety: OarpPlanner is stateless; artifacts are immutable.
#ifndef COVPLAN_PLANNER_OARP_OARP_PLANNER_H_
#define COVPLAN_PLANNER_OARP_OARP_PLANNER_H_

#include <memory>
#include <string_view>
#include <vector>

#include "planner/engine/planner.h"
#include "planner/partition/partitioner.h"
#include "planner/partition/rank.h"
#include "planner/tour/endpoint_graph.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/tour_solver.h"
#include "planner/tour/transitions.h"

namespace covplan {

struct OarpOptions final : PlannerOptions {
  PartitionSolver partition_solver =
      PartitionSolver::kPushRelabel;  // fastest exact (docs/benchmarks.md §1d)
  TourSolver tour_solver = TourSolver::kGtsp;
  // kFast/kDefault stop by themselves when the search converges (often well
  // within the budget); kThorough keeps improving until the budget is spent.
  GtspEffort tour_effort = GtspEffort::kDefault;
  absl::Status Validate() const override;
  std::string CacheText() const override;
};

// OARP's detail beside the planner-neutral plan.
class OarpDetail final : public PlannerDetail {
 public:
  std::vector<Rank> ranks;          // all ranks of the partition
  std::vector<int> rank_order;      // visiting order (indices into ranks)
  std::vector<bool> rank_reversed;  // per visit in rank_order: driven last->first
  size_t MemoryBytes() const override {
    return sizeof(*this) + ranks.capacity() * sizeof(Rank) + rank_order.capacity() * sizeof(int) +
           rank_reversed.capacity() / 8;
  }
};

class PartitionArtifact final : public Artifact {
 public:
  std::shared_ptr<const RankPartition> partition;
  std::string solver;
  double build_ms = 0.0;
  size_t MemoryBytes() const override { return sizeof(*this) + partition->MemoryBytes(); }
};

// Exactly one of `table` (all-pairs, small maps) and `graph` (sparse
// candidates, above EngineLimits::dense_transition_bytes) is set.
class TransitionArtifact final : public Artifact {
 public:
  std::shared_ptr<const TransitionTable> table;
  std::shared_ptr<const EndpointGraph> graph;
  double build_ms = 0.0;
  size_t MemoryBytes() const override {
    return sizeof(*this) + (table ? table->MemoryBytes() : 0) + (graph ? graph->MemoryBytes() : 0);
  }
};

// Bytes of OARP's dense path at `num_ranks`: the all-pairs table plus the
// GTSP instance and its search form (three V x V double matrices).
int64_t DenseTransitionBytes(int64_t num_ranks);
// Peak bytes of the sparse path: candidate graph, per-thread search scratch
// (octile and any-angle), tour state and the capped exact-length cache.
int64_t SparseTransitionBytes(int64_t grid_cells, int64_t num_ranks, int num_threads);

class OarpPlanner final : public Planner {
 public:
  static constexpr std::string_view kName = "oarp";
  std::string_view name() const override { return kName; }
  std::shared_ptr<const PlannerOptions> DefaultOptions() const override;
  absl::Status CheckOptions(const PlannerOptions& options) const override;
  absl::Status Prepare(const PlanContext& ctx) const override;
  absl::StatusOr<CoveragePlan> Plan(const PlanContext& ctx) const override;
  // The GTSP orderer only (the greedy order has nothing to warm-start).
  bool SupportsWarmStart(const PlannerOptions& options) const override;

 private:
  struct Artifacts {
    std::shared_ptr<const PartitionArtifact> partition;
    std::shared_ptr<const TransitionArtifact> transitions;
  };
  absl::StatusOr<Artifacts> GetArtifacts(const PlanContext& ctx, const OarpOptions& options) const;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_OARP_OARP_PLANNER_H_
