#include "planner/stc/stc_planner.h"

#include <tuple>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"

namespace covplan {

std::string StcOptions::CacheText() const {
  return absl::StrFormat("stc:tree=%d;sweep=%d;partial=%d;offset=%d", static_cast<int>(tree),
                         static_cast<int>(sweep_direction), static_cast<int>(partial_cells),
                         search_offset ? 1 : 0);
}

absl::Status StcOptions::Validate() const {
  if (tree != StcTreeMethod::kDfs && tree != StcTreeMethod::kPrim) {
    return absl::InvalidArgumentError("stc.tree: unknown tree method (DFS or PRIM)");
  }
  if (sweep_direction != SweepDirection::kHorizontal &&
      sweep_direction != SweepDirection::kVertical) {
    return absl::InvalidArgumentError(
        "stc.sweep_direction: unknown direction (HORIZONTAL or VERTICAL)");
  }
  if (partial_cells != PartialCells::kCover && partial_cells != PartialCells::kDiscard) {
    return absl::InvalidArgumentError("stc.partial_cells: unknown mode (COVER or DISCARD)");
  }
  if (tree == StcTreeMethod::kDfs && sweep_direction != SweepDirection::kHorizontal) {
    return absl::InvalidArgumentError(
        "stc.sweep_direction: only the PRIM tree has a sweep direction (stc.tree is DFS)");
  }
  return absl::OkStatus();
}

absl::StatusOr<CellIndex> DefaultStartCell(const Grid& drive, const Grid& cover) {
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (drive.free_flags()[i] && cover.free_flags()[i]) return drive.FromIndex(i);
  }
  return absl::NotFoundError("no cell to cover");
}

absl::StatusOr<StcOutcome> RunOfflineStc(const Grid& drive, const Grid& cover,
                                         const StcOptions& options, CellIndex start_cell,
                                         CellIndex end_cell, const StopToken& stop) {
  RETURN_IF_ERROR(options.Validate());
  std::vector<CellIndex> offsets = {{0, 0}};
  if (options.search_offset) offsets = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
  StcOutcome best;
  for (const CellIndex& offset : offsets) {
    if (best.detail != nullptr && stop.ShouldStop()) {
      best.stopped = true;
      break;
    }
    const CoarseGrid coarse(drive, cover, offset, options.partial_cells);
    const StcRoot root{coarse.CoarseOf(start_cell), coarse.PositionOf(start_cell)};
    const StcTree tree = options.tree == StcTreeMethod::kDfs
                             ? BuildDfsTree(coarse, root)
                             : BuildPrimTree(coarse, root, options.sweep_direction);
    std::vector<uint8_t> orphan;
    if (options.partial_cells == PartialCells::kCover) {
      orphan.assign(drive.size(), 0);
      for (int64_t i = 0; i < drive.size(); ++i) {
        const CellIndex c = drive.FromIndex(i);
        orphan[i] = cover.free_flags()[i] && coarse.IsOrphan(c);
      }
    }
    ASSIGN_OR_RETURN(StcWalk walk, WalkForest(drive, cover, CircumnavigateEach(coarse, tree),
                                              orphan, start_cell, end_cell, stop));
    // Most cells covered (differs only when partial cells are discarded),
    // then fewest moves, then fewest partly free coarse cells.
    const int64_t partial = tree.num_nodes - coarse.num_full_nodes();
    const bool better = best.detail == nullptr ||
                        std::make_tuple(-walk.covered_cells, walk.steps.size(), partial) <
                            std::make_tuple(-best.walk.covered_cells, best.walk.steps.size(),
                                            best.detail->partial_coarse_cells);
    if (!better) continue;
    auto d = std::make_shared<StcDetail>();
    d->tree = options.tree;
    d->sweep_direction = options.sweep_direction;
    d->partial_cells = options.partial_cells;
    d->offset = offset;
    d->coarse_cells = tree.num_nodes;
    d->full_coarse_cells = coarse.num_full_nodes();
    d->partial_coarse_cells = tree.num_nodes - coarse.num_full_nodes();
    d->tree_edges = tree.num_edges;
    for (uint8_t o : orphan) d->orphan_cells += o;
    d->trees = static_cast<int64_t>(tree.roots.size());
    d->extra_moves = walk.extra_moves;
    d->subcells_covered_twice = walk.cells_covered_twice;
    int64_t to_cover = 0;
    for (int64_t i = 0; i < drive.size(); ++i)
      to_cover += drive.free_flags()[i] && cover.free_flags()[i];
    d->discarded_cells = to_cover - walk.covered_cells;
    best.walk = std::move(walk);
    best.detail = std::move(d);
  }
  return best;
}

std::shared_ptr<const PlannerOptions> StcPlanner::DefaultOptions() const {
  return std::make_shared<const StcOptions>();
}

absl::Status StcPlanner::CheckOptions(const PlannerOptions& options) const {
  const auto* o = dynamic_cast<const StcOptions*>(&options);
  if (o == nullptr) return absl::InvalidArgumentError("planner 'stc' needs STC options (stc)");
  return o->Validate();
}

absl::StatusOr<CoveragePlan> StcPlanner::Plan(const PlanContext& ctx) const {
  const absl::Time t0 = absl::Now();
  const StcOptions& options = *static_cast<const StcOptions*>(ctx.options);
  const CommonOptions& common = *ctx.common;
  const Grid& drive = *ctx.area->drive;
  const Grid& cover = *ctx.area->cover;
  const RobotModel& robot = common.robot;
  CellIndex start_cell;
  if (robot.start) {
    ASSIGN_OR_RETURN(start_cell, JoinCell(drive, *robot.start, "start"));
  } else {
    absl::StatusOr<CellIndex> first = DefaultStartCell(drive, cover);
    if (!first.ok()) return absl::InvalidArgumentError("nothing to cover");
    start_cell = *first;
  }
  CellIndex end_cell = start_cell;
  if (robot.end) {
    ASSIGN_OR_RETURN(end_cell, JoinCell(drive, *robot.end, "end"));
  }
  ASSIGN_OR_RETURN(StcOutcome outcome,
                   RunOfflineStc(drive, cover, options, start_cell, end_cell, common.stop));

  CoveragePlan plan;
  plan.grid = ctx.area->drive;
  const CellIndex offset = outcome.detail->offset;
  const int coarse_cols = (drive.cols() + offset.col + 1) / 2;
  const std::optional<Pose2> end_pose = robot.end ? robot.end : robot.start;
  AppendWalk(
      drive, outcome.walk, robot.start, end_pose,
      [&](CellIndex c) {
        return ((c.row + offset.row) / 2) * coarse_cols + (c.col + offset.col) / 2;
      },
      &plan);
  if (outcome.stopped) {
    const TerminationLimit limit =
        common.stop.cancelled() ? TerminationLimit::kCancelled : TerminationLimit::kDeadline;
    plan.termination =
        Termination::LimitReached(limit, "stopped before every coarse-grid offset was tried");
  } else {
    plan.termination = Termination::Converged();
  }
  PlanStats& s = plan.stats;
  s.num_ranks = static_cast<int64_t>(plan.sweeps.size());
  s.tour_solver = options.tree == StcTreeMethod::kDfs ? "stc-dfs" : "stc-prim";
  s.tour_ms = absl::ToDoubleMilliseconds(absl::Now() - t0);
  plan.detail = std::move(outcome.detail);
  return plan;
}

}  // namespace covplan
