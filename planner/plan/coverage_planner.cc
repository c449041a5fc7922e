#include "planner/plan/coverage_planner.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/path_timing.h"
#include "planner/tour/rank_tour.h"
#include "planner/tour/transitions.h"

namespace covplan {
namespace {

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

// Keeps only the largest 4-connected free component: the robot cannot drive
// between components, so cells elsewhere are unreachable from any start.
Grid KeepLargestComponent(const Grid& grid, int64_t* dropped) {
  int32_t num = 0;
  std::vector<int32_t> comp = FreeComponents(grid, &num);
  std::vector<int64_t> size(num, 0);
  for (int32_t c : comp) {
    if (c >= 0) ++size[c];
  }
  const int32_t keep = static_cast<int32_t>(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<uint8_t> free(grid.size(), 0);
  *dropped = 0;
  for (int64_t i = 0; i < grid.size(); ++i) {
    free[i] = comp[i] == keep;
    *dropped += comp[i] >= 0 && comp[i] != keep;
  }
  return Grid(grid.rows(), grid.cols(), grid.cell_size(), grid.origin(), std::move(free),
              grid.walls(), grid.shared_obstacle_pixels());
}

}  // namespace

absl::Status DecompositionOptions::Validate() const { return grid.Validate(); }

std::string DecompositionOptions::CacheKey() const {
  return absl::StrFormat("cell=%.9g;minfree=%.9g;solver=%d", grid.cell_size, grid.min_free_fraction,
                         static_cast<int>(partition_solver));
}

size_t Decomposition::MemoryBytes() const {
  size_t bytes = sizeof(*this);
  if (grid) bytes += grid->MemoryBytes();
  if (partition) bytes += partition->MemoryBytes();
  if (transitions) bytes += transitions->MemoryBytes();
  return bytes;
}

absl::Status PlanOptions::Validate() const {
  RETURN_IF_ERROR(robot.Validate());
  if (!std::isfinite(time_limit_s) || time_limit_s < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("time limit must be a non-negative number of seconds, got %g", time_limit_s));
  }
  if (num_threads < 1 || num_threads > 256) {
    return absl::InvalidArgumentError(absl::StrFormat("threads must be in [1, 256], got %d", num_threads));
  }
  return decomposition().Validate();
}

DecompositionOptions PlanOptions::decomposition() const {
  DecompositionOptions d;
  d.grid.cell_size = robot.tool_width_m;
  d.grid.min_free_fraction = min_free_fraction;
  d.partition_solver = partition_solver;
  return d;
}

absl::StatusOr<std::shared_ptr<const Decomposition>> BuildDecomposition(
    const OccupancyMap& map, const DecompositionOptions& options, const StopToken& stop) {
  RETURN_IF_ERROR(options.Validate());
  if (options.max_ranks < 1) return absl::InvalidArgumentError("max_ranks must be >= 1");
  auto d = std::make_shared<Decomposition>();
  absl::Time t = absl::Now();
  ASSIGN_OR_RETURN(Grid full_grid, BuildGrid(map, options.grid));
  Grid grid = KeepLargestComponent(full_grid, &d->unreachable_free_cells);
  d->grid = std::make_shared<const Grid>(std::move(grid));
  d->map_free_area_m2 = map.FreeAreaM2();
  d->covered_free_area_ratio = CoveredFreeAreaRatio(map, *d->grid);
  d->grid_ms = MsSince(t);

  t = absl::Now();
  ASSIGN_OR_RETURN(RankPartition partition,
                   MakePartitioner(options.partition_solver)->Partition(*d->grid, stop));
  d->partition = std::make_shared<const RankPartition>(std::move(partition));
  d->partition_ms = MsSince(t);
  const int64_t num_ranks = static_cast<int64_t>(d->partition->ranks.size());
  if (num_ranks > options.max_ranks) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the map needs %d coverage ranks at tool width %g m, above the limit of %d: the "
        "all-pairs transition table would take about %d MiB; use a wider tool or split the map",
        num_ranks, options.grid.cell_size, options.max_ranks,
        TransitionTable::EstimateBytes(static_cast<int>(2 * num_ranks)) >> 20));
  }

  t = absl::Now();
  ASSIGN_OR_RETURN(d->transitions,
                   TransitionTable::Build(*d->grid, d->partition->ranks, stop, options.num_threads));
  d->transitions_ms = MsSince(t);
  return std::shared_ptr<const Decomposition>(std::move(d));
}

absl::StatusOr<CoveragePlan> PlanOnDecomposition(const Decomposition& d, const PlanOptions& options) {
  RETURN_IF_ERROR(options.Validate());
  if (!d.grid || !d.partition || !d.transitions) {
    return absl::InvalidArgumentError("decomposition is incomplete");
  }
  const absl::Time start = absl::Now();
  CoveragePlan plan;
  plan.grid = d.grid;
  plan.ranks = d.partition->ranks;
  ASSIGN_OR_RETURN(RankTourCost cost, RankTourCost::Create(*d.grid, d.partition->ranks,
                                                           *d.transitions, options.robot,
                                                           options.stop));
  OrdererOptions oo;
  oo.time_limit_s = options.time_limit_s;
  oo.seed = options.seed;
  oo.num_threads = options.num_threads;
  oo.effort = options.tour_effort;
  std::unique_ptr<RankOrderer> orderer;
  if (options.tour_solver == TourSolver::kGreedy) {
    orderer = std::make_unique<GreedyOrderer>();
  } else {
    orderer = std::make_unique<GtspOrderer>(oo);
  }
  ASSIGN_OR_RETURN(RankTour tour, orderer->Order(cost, options.stop));
  for (int v : tour.vertices) {
    plan.rank_order.push_back(v / 2);
    plan.rank_reversed.push_back(v % 2 == 1);
  }
  plan.path = cost.BuildPath(tour.vertices);

  PlanStats& s = plan.stats;
  s = ComputePathStats(plan.path, options.robot);
  s.num_ranks = static_cast<int64_t>(plan.ranks.size());
  s.grid_rows = d.grid->rows();
  s.grid_cols = d.grid->cols();
  s.free_cells = d.grid->CountFree();
  s.unreachable_free_cells = d.unreachable_free_cells;
  s.map_free_area_m2 = d.map_free_area_m2;
  s.covered_free_area_ratio = d.covered_free_area_ratio;
  s.grid_ms = d.grid_ms;
  s.partition_ms = d.partition_ms;
  s.transitions_ms = d.transitions_ms;
  s.tour_ms = MsSince(start);
  s.tour_cut_short = tour.cut_short;
  s.partition_solver = MakePartitioner(options.partition_solver)->name();
  s.tour_solver = std::string(orderer->name());
  s.planning_ms = s.grid_ms + s.partition_ms + s.transitions_ms + s.tour_ms;
  return plan;
}

PlanStats ComputePathStats(const std::vector<Waypoint>& path, const RobotModel& robot) {
  PlanStats s;
  if (path.empty()) return s;
  double heading = path[0].theta;
  for (size_t i = 1; i < path.size(); ++i) {
    const Waypoint& a = path[i - 1];
    const Waypoint& b = path[i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const double change = HeadingChange(heading, b.theta);
    if (change > kTurnEpsilonRad) {
      ++s.num_turns;
      s.turning_time_s += robot.TurnTime(change);
    }
    heading = b.theta;
    s.estimated_duration_s += robot.StraightTime(len);
    (b.kind == SegmentKind::kCoverage ? s.coverage_length_m : s.transition_length_m) += len;
  }
  s.estimated_duration_s += s.turning_time_s;
  return s;
}

absl::StatusOr<CoveragePlan> PlanCoverage(const OccupancyMap& map, const PlanOptions& options) {
  RETURN_IF_ERROR(options.Validate());
  DecompositionOptions dopt = options.decomposition();
  dopt.num_threads = options.num_threads;
  ASSIGN_OR_RETURN(std::shared_ptr<const Decomposition> d, BuildDecomposition(map, dopt, options.stop));
  return PlanOnDecomposition(*d, options);
}

}  // namespace covplan
