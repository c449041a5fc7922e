#include "planner/oarp/oarp_planner.h"

#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/rank_tour.h"
#include "planner/tour/sparse_tour.h"
#include "planner/tour/tour_model.h"

namespace covplan {
namespace {

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

const OarpOptions& Options(const PlanContext& ctx) {
  return *static_cast<const OarpOptions*>(ctx.options);
}

constexpr int kCandidateNeighbours = 20;
constexpr int64_t kCachedPairs = 4'000'000;
constexpr int64_t kBytesPerCachedPair = 40;  // unordered_map node + bucket

}  // namespace

int64_t DenseTransitionBytes(int64_t num_ranks) {
  const int64_t v = 2 * std::min<int64_t>(num_ranks, 1 << 28) + 2;
  return TransitionTable::EstimateBytes(static_cast<int>(std::min<int64_t>(v, 1 << 30))) +
         3 * v * v * 8;
}

int64_t SparseTransitionBytes(int64_t grid_cells, int64_t num_ranks, int num_threads) {
  const int threads = std::max(1, num_threads);
  return EndpointGraph::EstimateBytes(grid_cells, 2 * num_ranks, kCandidateNeighbours, threads) +
         threads * grid_cells * AnyAngleSearch::kBytesPerCell +        // tour runs, then the legs
         threads * (num_ranks * 2 * 64 + kSparseTourBytesPerThread) +  // tour state per run
         num_ranks * 2 * 128 +                                         // legs and waypoints
         kCachedPairs * kBytesPerCachedPair;
}

absl::Status OarpOptions::Validate() const {
  if (partition_solver != PartitionSolver::kMinCut && partition_solver != PartitionSolver::kLp &&
      partition_solver != PartitionSolver::kMatching &&
      partition_solver != PartitionSolver::kPushRelabel) {
    return absl::InvalidArgumentError("oarp.partition_solver: unknown solver");
  }
  return CheckTourSolver(tour_solver, "oarp.tour_solver");
}

std::string OarpOptions::CacheText() const {
  return absl::StrFormat("oarp:partition=%d;tour=%d;effort=%d", static_cast<int>(partition_solver),
                         static_cast<int>(tour_solver), static_cast<int>(tour_effort));
}

bool OarpPlanner::SupportsWarmStart(const PlannerOptions& options) const {
  return static_cast<const OarpOptions&>(options).tour_solver == TourSolver::kGtsp;
}

std::shared_ptr<const PlannerOptions> OarpPlanner::DefaultOptions() const {
  return std::make_shared<const OarpOptions>();
}

absl::Status OarpPlanner::CheckOptions(const PlannerOptions& options) const {
  const auto* o = dynamic_cast<const OarpOptions*>(&options);
  if (o == nullptr) return absl::InvalidArgumentError("planner 'oarp' needs OARP options (oarp)");
  return o->Validate();
}

absl::StatusOr<OarpPlanner::Artifacts> OarpPlanner::GetArtifacts(const PlanContext& ctx,
                                                                 const OarpOptions& options) const {
  const CommonOptions& common = *ctx.common;
  const CoverageArea& area = *ctx.area;
  std::unique_ptr<RankPartitioner> partitioner = MakePartitioner(options.partition_solver);
  const auto pkey =
      ctx.area_key.Derive<PartitionArtifact>("partition", std::string(partitioner->name()));
  bool hit = false;
  Artifacts a;
  ASSIGN_OR_RETURN(
      a.partition,
      GetOrBuild(
          *ctx.cache, pkey, common.stop,
          [&](const StopToken& stop) -> absl::StatusOr<std::shared_ptr<const PartitionArtifact>> {
            const absl::Time t = absl::Now();
            ASSIGN_OR_RETURN(RankPartition p, partitioner->Partition(*area.cover, stop));
            auto out = std::make_shared<PartitionArtifact>();
            out->partition = std::make_shared<const RankPartition>(std::move(p));
            out->solver = std::string(partitioner->name());
            out->build_ms = MsSince(t);
            return std::shared_ptr<const PartitionArtifact>(std::move(out));
          },
          &hit));
  if (!hit && ctx.all_cached != nullptr) *ctx.all_cached = false;
  const std::vector<Rank>& ranks = a.partition->partition->ranks;
  const int64_t num_ranks = static_cast<int64_t>(ranks.size());
  if (num_ranks > ctx.limits.max_ranks) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the map needs %d coverage ranks at tool width %g m, above the limit of %d (--max_ranks); "
        "use a wider tool or split the map",
        num_ranks, area.cover->cell_size(), ctx.limits.max_ranks));
  }
  // Dense exact transitions while they fit their budget, sparse above.
  const int64_t dense_bytes = DenseTransitionBytes(num_ranks);
  const bool sparse = dense_bytes > ctx.limits.dense_transition_bytes;
  const int64_t need =
      sparse ? SparseTransitionBytes(area.drive->size(), num_ranks, common.num_threads)
             : dense_bytes;
  if (need > ctx.limits.max_transition_bytes) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "the map needs %d coverage ranks at tool width %g m on a %d-cell drive grid: the %s "
        "transitions would take about %d MiB, above the transition memory budget of %d MiB "
        "(--max_transition_mb); use a wider tool or split the map",
        num_ranks, area.cover->cell_size(), area.drive->size(), sparse ? "sparse" : "all-pairs",
        need >> 20, ctx.limits.max_transition_bytes >> 20));
  }
  if (sparse) {
    const auto ckey =
        pkey.Derive<TransitionArtifact>("candidates", absl::StrFormat("%d", kCandidateNeighbours));
    ASSIGN_OR_RETURN(a.transitions,
                     GetOrBuild(
                         *ctx.cache, ckey, common.stop,
                         [&](const StopToken& stop)
                             -> absl::StatusOr<std::shared_ptr<const TransitionArtifact>> {
                           const absl::Time t = absl::Now();
                           auto out = std::make_shared<TransitionArtifact>();
                           std::vector<CellIndex> endpoints;
                           endpoints.reserve(2 * ranks.size());
                           for (const Rank& r : ranks) {
                             endpoints.push_back(r.first);
                             endpoints.push_back(r.last);
                           }
                           EndpointGraph::Options go;
                           go.neighbours = kCandidateNeighbours;
                           ASSIGN_OR_RETURN(out->graph,
                                            EndpointGraph::Build(*area.drive, std::move(endpoints),
                                                                 go, stop, common.num_threads));
                           out->build_ms = MsSince(t);
                           return std::shared_ptr<const TransitionArtifact>(std::move(out));
                         },
                         &hit));
    if (!hit && ctx.all_cached != nullptr) *ctx.all_cached = false;
    return a;
  }
  const auto tkey = pkey.Derive<TransitionArtifact>("transitions", "");
  ASSIGN_OR_RETURN(
      a.transitions,
      GetOrBuild(
          *ctx.cache, tkey, common.stop,
          [&](const StopToken& stop) -> absl::StatusOr<std::shared_ptr<const TransitionArtifact>> {
            const absl::Time t = absl::Now();
            auto out = std::make_shared<TransitionArtifact>();
            ASSIGN_OR_RETURN(out->table,
                             TransitionTable::Build(*area.drive, ranks, stop, common.num_threads));
            out->build_ms = MsSince(t);
            return std::shared_ptr<const TransitionArtifact>(std::move(out));
          },
          &hit));
  if (!hit && ctx.all_cached != nullptr) *ctx.all_cached = false;
  return a;
}

absl::Status OarpPlanner::Prepare(const PlanContext& ctx) const {
  return GetArtifacts(ctx, Options(ctx)).status();
}

absl::StatusOr<CoveragePlan> OarpPlanner::Plan(const PlanContext& ctx) const {
  const OarpOptions& options = Options(ctx);
  const CommonOptions& common = *ctx.common;
  ASSIGN_OR_RETURN(Artifacts a, GetArtifacts(ctx, options));
  const absl::Time start = absl::Now();
  const Grid& drive = *ctx.area->drive;
  const std::vector<Rank>& ranks = a.partition->partition->ranks;
  std::vector<int> vertices;
  CoveragePlan plan;
  std::string tour_solver;
  if (a.transitions->graph != nullptr) {
    SparseTourOptions so;
    so.time_limit_s = common.time_limit_s;
    so.seed = common.seed;
    so.num_threads = common.num_threads;
    so.local_search = options.tour_solver == TourSolver::kGtsp;
    so.until_limit = options.tour_effort == GtspEffort::kThorough;
    if (options.tour_effort == GtspEffort::kFast) so.kicks_per_rank = 1.0, so.min_kicks = 500;
    so.max_cached_pairs = kCachedPairs;
    if (ctx.warm_tour != nullptr && SupportsWarmStart(options)) {
      so.warm_vertices = *ctx.warm_tour;
      so.warm_kicks = ctx.warm_trials != 0;  // a new start pose: the descent only
    }
    ASSIGN_OR_RETURN(SparseTour tour, PlanSparseRankTour(drive, ranks, *a.transitions->graph,
                                                         common.robot, so, common.stop));
    vertices = std::move(tour.vertices);
    plan.path = std::move(tour.path);
    plan.termination = tour.termination;
    tour_solver = so.local_search ? "sparse" : "sparse-greedy";
    if (SupportsWarmStart(options)) plan.tour_vertices = vertices;
  } else {
    ASSIGN_OR_RETURN(RankTourCost cost, RankTourCost::Create(drive, ranks, *a.transitions->table,
                                                             common.robot, common.stop));
    OrdererOptions oo;
    oo.time_limit_s = common.time_limit_s;
    oo.seed = common.seed;
    oo.num_threads = common.num_threads;
    oo.effort = options.tour_effort;
    if (ctx.warm_tour != nullptr && SupportsWarmStart(options)) {
      oo.warm_order = *ctx.warm_tour;
      oo.warm_trials = ctx.warm_trials;
    }
    std::unique_ptr<TourOrderer> orderer;
    if (options.tour_solver == TourSolver::kGreedy) {
      orderer = std::make_unique<GreedyOrderer>();
    } else {
      orderer = std::make_unique<GtspOrderer>(oo);
    }
    ASSIGN_OR_RETURN(TourOrder tour, orderer->Order(cost, common.stop));
    vertices = std::move(tour.vertices);
    plan.path = cost.BuildPath(vertices);
    plan.termination = tour.termination;
    tour_solver = std::string(orderer->name());
    if (SupportsWarmStart(options)) plan.tour_vertices = vertices;
  }

  plan.grid = ctx.area->drive;
  auto detail = std::make_shared<OarpDetail>();
  detail->ranks = ranks;
  for (int v : vertices) {
    detail->rank_order.push_back(v / 2);
    detail->rank_reversed.push_back(v % 2 == 1);
  }
  for (size_t i = 0; i < plan.path.size(); ++i) {
    const Waypoint& w = plan.path[i];
    if (w.kind != SegmentKind::kCoverage) continue;
    const Rank& r = ranks[w.rank];
    CoverageSweep sweep;
    sweep.waypoint = static_cast<int>(i);
    for (int k = 0; k < r.NumCells(); ++k) {
      sweep.cells.push_back(r.orientation == Orientation::kHorizontal
                                ? CellIndex{r.first.row, r.first.col + k}
                                : CellIndex{r.first.row + k, r.first.col});
    }
    plan.sweeps.push_back(std::move(sweep));
  }
  plan.detail = std::move(detail);
  PlanStats& s = plan.stats;
  s.num_ranks = static_cast<int64_t>(ranks.size());
  s.partition_ms = a.partition->build_ms;
  s.transitions_ms = a.transitions->build_ms;
  s.tour_ms = MsSince(start);
  s.partition_solver = a.partition->solver;
  s.tour_solver = tour_solver;
  return plan;
}

}  // namespace covplan
