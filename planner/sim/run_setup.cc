#include "planner/sim/run_setup.h"

#include <cstdint>
#include <utility>
#include <vector>

#include "planner/common/status_macros.h"
#include "planner/sim/clutter.h"
#include "planner/sim/map_frame.h"
#include "planner/tour/grid_paths.h"

namespace covplan::sim_internal {

absl::StatusOr<TrueSite> MakeTrueSite(const OccupancyMap& known, const OccupancyMap& truth,
                                      const std::vector<Point2>& clear_at,
                                      const PlanOptions& plan) {
  TrueSite site;
  site.truth = &truth;
  for (const Point2& p : clear_at) {
    OccupancyMap probe = site.cleared != nullptr ? *site.cleared : truth;
    const int64_t freed = ClearAround(known, p, plan.robot.tool_width_m, &probe);
    if (freed > 0) {
      site.cleared = std::make_shared<OccupancyMap>(std::move(probe));
      site.cleared_px += freed;
    }
  }
  const GridOptions go = PlanGridOptions(plan);
  ASSIGN_OR_RETURN(site.frame, PlanGridFrame(site.map(), go));
  site.fractions = CellFreeFractions(site.map(), site.frame);
  ASSIGN_OR_RETURN(site.grid, BuildGridFromFractions(site.map(), go, site.frame, site.fractions));
  return site;
}

absl::StatusOr<std::vector<uint8_t>> Candidates(const Grid& drive, const Grid& true_grid) {
  if (drive.rows() != true_grid.rows() || drive.cols() != true_grid.cols()) {
    return absl::InternalError("the plan's grid and the true grid differ in shape");
  }
  std::vector<uint8_t> candidate(static_cast<size_t>(drive.size()), 0);
  for (int64_t i = 0; i < drive.size(); ++i) {
    candidate[i] = drive.free_flags()[i] && !true_grid.free_flags()[i];
  }
  return candidate;
}

double CoveredFreeAreaRatio(const TrueSite& site, const std::vector<uint8_t>& swept) {
  const int64_t true_free = site.map().CountFree();
  const double px_per_cell = site.frame.px_per_cell;
  double swept_free_px = 0.0;
  for (size_t i = 0; i < swept.size() && i < site.fractions.size(); ++i) {
    if (swept[i]) swept_free_px += site.fractions[i] * px_per_cell * px_per_cell;
  }
  return true_free > 0 ? swept_free_px / true_free : 0.0;
}

Grid ReachableModel(const TrueSite& site, const Grid& drive, const std::vector<Point2>& starts,
                    const std::vector<uint8_t>* closed) {
  std::vector<uint8_t> free(drive.free_flags().begin(), drive.free_flags().end());
  for (size_t c = 0; c < free.size() && c < site.grid.free_flags().size(); ++c) {
    free[c] = free[c] && site.grid.free_flags()[c];
    if (closed != nullptr && c < closed->size() && (*closed)[c]) free[c] = 0;
  }
  const Grid both = drive.WithFreeFlags(free);
  int32_t num = 0;
  const std::vector<int32_t> comp = FreeComponents(both, &num);
  std::vector<uint8_t> held(static_cast<size_t>(num), 0);
  for (const Point2& p : starts) {
    const CellIndex c = both.CellAt(p);
    if (both.InBounds(c.row, c.col) && comp[both.Index(c.row, c.col)] >= 0) {
      held[comp[both.Index(c.row, c.col)]] = 1;
    }
  }
  for (size_t c = 0; c < free.size(); ++c) free[c] = comp[c] >= 0 && held[comp[c]];
  return drive.WithFreeFlags(std::move(free));
}

FloorMeasure DrivenFloor(const TrueSite& site, const Grid& model, const Area* no_go,
                         const Area* regions,
                         const std::vector<const std::vector<Waypoint>*>& paths) {
  const FloorReach reach = ComputeFloorReach(site.map(), model, no_go, regions);
  return MeasureFloor(reach, paths, /*keep_missed=*/false);
}

absl::StatusOr<RetainedPlan> LocalPlanSource::InitialPlan(const OccupancyMap& known,
                                                          const PlanOptions& options) {
  ASSIGN_OR_RETURN(EngineResult planned, PlanCoverageWithArea(known, options));
  RetainedPlan retained;
  retained.plan_id = "simulation";
  retained.map_id = "known";
  retained.plan = std::move(planned.plan);
  retained.request = options.ToRequest();
  retained.area = std::move(planned.area);
  return retained;
}

absl::StatusOr<ReplanResult> LocalPlanSource::Replan(const RetainedPlan& plan,
                                                     const RobotProgress& at,
                                                     const Observations& seen,
                                                     const ReplanOptions& options) {
  return covplan::Replan(plan, at, seen, options, &estimator_);
}

}  // namespace covplan::sim_internal
