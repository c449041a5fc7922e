#include "planner/oarp/oarp_planner.h"

#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/rank_tour.h"
#include "planner/tour/tour_model.h"

namespace covplan {
namespace {

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

const OarpOptions& Options(const PlanContext& ctx) {
  return *static_cast<const OarpOptions*>(ctx.options);
}

}  // namespace

absl::Status OarpOptions::Validate() const {
  if (partition_solver != PartitionSolver::kMinCut && partition_solver != PartitionSolver::kLp &&
      partition_solver != PartitionSolver::kMatching) {
    return absl::InvalidArgumentError("oarp.partition_solver: unknown solver");
  }
  if (tour_solver != TourSolver::kGreedy && tour_solver != TourSolver::kGtsp) {
    return absl::InvalidArgumentError("oarp.tour_solver: unknown solver");
  }
  return absl::OkStatus();
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
  const auto pkey = ctx.area_key.Derive<PartitionArtifact>("partition", std::string(partitioner->name()));
  bool hit = false;
  Artifacts a;
  ASSIGN_OR_RETURN(a.partition, GetOrBuild(*ctx.cache, pkey, common.stop,
                                           [&](const StopToken& stop)
                                               -> absl::StatusOr<std::shared_ptr<const PartitionArtifact>> {
                                             const absl::Time t = absl::Now();
                                             ASSIGN_OR_RETURN(RankPartition p,
                                                              partitioner->Partition(*area.cover, stop));
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
        "the map needs %d coverage ranks at tool width %g m, above the limit of %d: the "
        "all-pairs transition table would take about %d MiB; use a wider tool or split the map",
        num_ranks, area.cover->cell_size(), ctx.limits.max_ranks,
        TransitionTable::EstimateBytes(static_cast<int>(2 * num_ranks)) >> 20));
  }
  const auto tkey = pkey.Derive<TransitionArtifact>("transitions", "");
  ASSIGN_OR_RETURN(a.transitions, GetOrBuild(*ctx.cache, tkey, common.stop,
                                             [&](const StopToken& stop)
                                                 -> absl::StatusOr<std::shared_ptr<const TransitionArtifact>> {
                                               const absl::Time t = absl::Now();
                                               auto out = std::make_shared<TransitionArtifact>();
                                               ASSIGN_OR_RETURN(out->table,
                                                                TransitionTable::Build(*area.drive, ranks, stop,
                                                                                       common.num_threads));
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

  CoveragePlan plan;
  plan.grid = ctx.area->drive;
  auto detail = std::make_shared<OarpDetail>();
  detail->ranks = ranks;
  for (int v : tour.vertices) {
    detail->rank_order.push_back(v / 2);
    detail->rank_reversed.push_back(v % 2 == 1);
  }
  plan.path = cost.BuildPath(tour.vertices);
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
  plan.termination = tour.termination;
  plan.detail = std::move(detail);
  if (SupportsWarmStart(options)) plan.tour_vertices = std::move(tour.vertices);
  PlanStats& s = plan.stats;
  s.num_ranks = static_cast<int64_t>(ranks.size());
  s.partition_ms = a.partition->build_ms;
  s.transitions_ms = a.transitions->build_ms;
  s.tour_ms = MsSince(start);
  s.partition_solver = a.partition->solver;
  s.tour_solver = std::string(orderer->name());
  return plan;
}

}  // namespace covplan
