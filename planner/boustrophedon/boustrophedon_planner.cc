#include "planner/boustrophedon/boustrophedon_planner.h"

#include <array>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/boustrophedon/cell_tour.h"
#include "planner/common/status_macros.h"
#include "planner/tour/polyline_tour.h"
#include "planner/tour/tour_model.h"

namespace covplan {
namespace {

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

const BoustrophedonOptions& Options(const PlanContext& ctx) {
  return *static_cast<const BoustrophedonOptions*>(ctx.options);
}

}  // namespace

absl::Status BoustrophedonOptions::Validate() const {
  if (sweep_axis != BoustrophedonAxis::kAuto && sweep_axis != BoustrophedonAxis::kVertical &&
      sweep_axis != BoustrophedonAxis::kHorizontal) {
    return absl::InvalidArgumentError("boustrophedon.sweep_axis: unknown axis");
  }
  return CheckTourSolver(tour_solver, "boustrophedon.tour_solver");
}

std::string BoustrophedonOptions::CacheText() const {
  return absl::StrFormat("boustrophedon:axis=%d;tour=%d;effort=%d", static_cast<int>(sweep_axis),
                         static_cast<int>(tour_solver), static_cast<int>(tour_effort));
}

size_t BoustrophedonDetail::MemoryBytes() const {
  size_t bytes = sizeof(*this) + cell_order.capacity() * sizeof(int) +
                 cell_reversed.capacity() / 8 + cell_mirrored.capacity() / 8;
  for (const BoustrophedonCellInfo& c : cells)
    bytes += sizeof(c) + c.cell.columns.capacity() * sizeof(RowInterval);
  return bytes;
}

std::shared_ptr<const PlannerOptions> BoustrophedonPlanner::DefaultOptions() const {
  return std::make_shared<const BoustrophedonOptions>();
}

absl::Status BoustrophedonPlanner::CheckOptions(const PlannerOptions& options) const {
  const auto* o = dynamic_cast<const BoustrophedonOptions*>(&options);
  if (o == nullptr) {
    return absl::InvalidArgumentError(
        "planner 'boustrophedon' needs boustrophedon options (boustrophedon)");
  }
  return o->Validate();
}

absl::StatusOr<std::shared_ptr<const DecompositionArtifact>> BoustrophedonPlanner::GetDecomposition(
    const PlanContext& ctx) const {
  const auto key = ctx.area_key.Derive<DecompositionArtifact>("bcd", "");
  bool hit = false;
  ASSIGN_OR_RETURN(
      std::shared_ptr<const DecompositionArtifact> d,
      GetOrBuild(
          *ctx.cache, key, ctx.common->stop,
          [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const DecompositionArtifact>> {
            const absl::Time t = absl::Now();
            auto out = std::make_shared<DecompositionArtifact>();
            out->decomposition =
                std::make_shared<const BoustrophedonDecomposition>(Decompose(*ctx.area->cover));
            out->build_ms = MsSince(t);
            return std::shared_ptr<const DecompositionArtifact>(std::move(out));
          },
          &hit));
  if (!hit && ctx.all_cached != nullptr) *ctx.all_cached = false;
  const int64_t n = static_cast<int64_t>(d->decomposition->cells.size());
  if (n == 0) return absl::InvalidArgumentError("no cells to cover: the coverage area is empty");
  // Four entry corners per cell: the all-pairs transition table has 4n
  // endpoints and must fit the transition memory budget.
  const int64_t table_bytes =
      TransitionTable::EstimateBytes(static_cast<int>(std::min<int64_t>(4 * n, 1 << 30)));
  if (table_bytes > ctx.limits.max_transition_bytes) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "the map decomposes into %d boustrophedon cells at tool width %g m: the transition table "
        "over "
        "their corners would take about %d MiB, above the transition memory budget of %d MiB "
        "(--max_transition_mb); use a wider tool or split the map",
        n, ctx.area->cover->cell_size(), table_bytes >> 20, ctx.limits.max_transition_bytes >> 20));
  }
  return d;
}

absl::Status BoustrophedonPlanner::Prepare(const PlanContext& ctx) const {
  return GetDecomposition(ctx).status();
}

absl::StatusOr<CoveragePlan> BoustrophedonPlanner::Plan(const PlanContext& ctx) const {
  const BoustrophedonOptions& options = Options(ctx);
  const CommonOptions& common = *ctx.common;
  ASSIGN_OR_RETURN(std::shared_ptr<const DecompositionArtifact> d, GetDecomposition(ctx));
  const absl::Time start = absl::Now();
  const Grid& cover = *ctx.area->cover;
  const Grid& drive = *ctx.area->drive;

  auto detail = std::make_shared<BoustrophedonDetail>();
  std::optional<SweepAxis> forced;
  if (options.sweep_axis == BoustrophedonAxis::kVertical) forced = SweepAxis::kVertical;
  if (options.sweep_axis == BoustrophedonAxis::kHorizontal) forced = SweepAxis::kHorizontal;
  std::vector<std::array<PolylineElement, 2>> elements;
  for (size_t i = 0; i < d->decomposition->cells.size(); ++i) {
    const BcdCell& cell = d->decomposition->cells[i];
    SweepLines lines = ChooseSweepLines(cover, cell, forced);
    detail->cells.push_back({cell, lines.axis, static_cast<int>(lines.lines.size())});
    elements.push_back({OxPlowElement(cover, lines, static_cast<int>(i), false),
                        OxPlowElement(cover, lines, static_cast<int>(i), true)});
  }
  Pose2 start_pose;
  if (common.robot.start.has_value()) {
    start_pose = *common.robot.start;
  } else {
    const Point2 p = elements[0][0].points[0];
    const Point2 q = elements[0][0].points.size() > 1 ? elements[0][0].points[1] : p;
    start_pose = {p.x, p.y, q.y != p.y || q.x != p.x ? std::atan2(q.y - p.y, q.x - p.x) : M_PI / 2};
  }
  const std::optional<Pose2> end_pose = common.robot.end;
  const absl::Time t_model = absl::Now();
  absl::StatusOr<CellTourModel> model = CellTourModel::Create(
      drive, std::move(elements), start_pose, end_pose,
      std::make_shared<TravelTimeCost>(common.robot), common.stop, common.num_threads);
  if (!model.ok()) {
    if (absl::IsFailedPrecondition(model.status())) {
      return absl::InternalError(absl::StrCat("boustrophedon: ", model.status().message()));
    }
    return model.status();
  }
  const double model_ms = MsSince(t_model);
  OrdererOptions oo;
  oo.time_limit_s = common.time_limit_s;
  oo.seed = common.seed;
  oo.num_threads = common.num_threads;
  oo.effort = options.tour_effort;
  std::unique_ptr<TourOrderer> orderer;
  if (options.tour_solver == TourSolver::kGreedy) {
    orderer = std::make_unique<GreedyOrderer>();
  } else {
    orderer = std::make_unique<GtspOrderer>(oo);
  }
  ASSIGN_OR_RETURN(TourOrder tour, orderer->Order(*model, common.stop));

  CoveragePlan plan;
  plan.grid = ctx.area->drive;
  model->BuildPath(tour.vertices, &plan.path, &plan.sweeps);
  for (int v : tour.vertices) {
    detail->cell_order.push_back(v / 4);
    detail->cell_mirrored.push_back((v / 2) % 2 == 1);
    detail->cell_reversed.push_back(v % 2 == 1);
  }
  plan.termination = tour.termination;
  plan.detail = std::move(detail);
  PlanStats& s = plan.stats;
  s.num_ranks = static_cast<int64_t>(plan.sweeps.size());
  s.partition_ms = d->build_ms;
  s.transitions_ms = model_ms;
  s.tour_ms = MsSince(start) - model_ms;
  s.partition_solver = "boustrophedon";
  s.tour_solver = std::string(orderer->name());
  return plan;
}

}  // namespace covplan
