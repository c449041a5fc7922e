#include "planner/sim/simulator.h"

#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/grid/grid.h"
#include "planner/sim/clutter.h"
#include "planner/sim/drive.h"
#include "planner/sim/map_frame.h"

namespace covplan {

absl::Status SimulationOptions::Validate() const {
  if (!(sensor_range_m > 0.0 && sensor_range_m <= 1000.0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("sensor_range_m must be in (0, 1000] m, got %g", sensor_range_m));
  }
  if (!(step_s > 0.0 && step_s <= 60.0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("step_s must be in (0, 60] s, got %g", step_s));
  }
  if (max_replans < 0) return absl::InvalidArgumentError("max_replans must be >= 0");
  if (!(replan_tour_time_limit_s > 0.0 && replan_tour_time_limit_s <= 3600.0)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "replan_tour_time_limit_s must be in (0, 3600] s, got %g", replan_tour_time_limit_s));
  }
  if (!(max_time_factor > 0.0 && std::isfinite(max_time_factor))) {
    return absl::InvalidArgumentError("max_time_factor must be a positive number");
  }
  if (!(recharge_s >= 0.0 && std::isfinite(recharge_s))) {
    return absl::InvalidArgumentError(
        absl::StrFormat("recharge_s must be a finite value >= 0 s, got %g", recharge_s));
  }
  if (plan.battery) RETURN_IF_ERROR(plan.battery->Validate());
  return plan.robot.Validate();
}

namespace {
// Plans and replans in process.
class LocalPlanSource final : public PlanSource {
 public:
  absl::StatusOr<RetainedPlan> InitialPlan(const OccupancyMap& known,
                                           const PlanOptions& options) override {
    ASSIGN_OR_RETURN(EngineResult planned, PlanCoverageWithArea(known, options));
    RetainedPlan retained;
    retained.plan_id = "simulation";
    retained.map_id = "known";
    retained.plan = std::move(planned.plan);
    retained.request = options.ToRequest();
    retained.area = std::move(planned.area);
    return retained;
  }
  absl::StatusOr<ReplanResult> Replan(const RetainedPlan& plan, const RobotProgress& at,
                                      const Observations& seen,
                                      const ReplanOptions& options) override {
    return covplan::Replan(plan, at, seen, options, &estimator_);
  }

 private:
  ReplanEstimator estimator_;
};
}  // namespace

absl::StatusOr<SimulationResult> Simulate(const OccupancyMap& known, const OccupancyMap& truth,
                                          const SimulationOptions& options, PlanSource* source) {
  RETURN_IF_ERROR(options.Validate());
  RETURN_IF_ERROR(sim_internal::CheckSameFrame(known, truth));
  LocalPlanSource local;
  if (source == nullptr) source = &local;
  ASSIGN_OR_RETURN(RetainedPlan retained, source->InitialPlan(known, options.plan));
  if (retained.plan.grid == nullptr || retained.plan.path.empty()) {
    return absl::InternalError("the initial plan has no grid or no path");
  }
  // Nothing stands where the robot starts or on its dock (the end pose).
  // Battery runs start and end at the station, which the true map itself
  // must leave free (checked below; the CLI keeps its clutter off it).
  std::shared_ptr<OccupancyMap> cleared;
  int64_t cleared_px = 0;
  for (const Waypoint* w : {&retained.plan.path.front(), &retained.plan.path.back()}) {
    if (options.plan.battery) break;
    OccupancyMap probe = cleared != nullptr ? *cleared : truth;
    const int64_t freed = ClearAround(known, {w->x, w->y}, options.plan.robot.tool_width_m, &probe);
    if (freed > 0) cleared = std::make_shared<OccupancyMap>(std::move(probe)), cleared_px += freed;
  }
  const OccupancyMap& true_map = cleared != nullptr ? *cleared : truth;
  const GridOptions go = sim_internal::PlanGridOptions(options.plan);
  ASSIGN_OR_RETURN(GridFrame frame, PlanGridFrame(true_map, go));
  const std::vector<double> fractions = CellFreeFractions(true_map, frame);
  ASSIGN_OR_RETURN(Grid true_grid, BuildGridFromFractions(true_map, go, frame, fractions));
  if (options.plan.battery) {
    // The robot must be able to dock: nothing the sensor could find there.
    const Pose2& st = options.plan.battery->station;
    const CellIndex cell = true_grid.CellAt({st.x, st.y});
    if (!true_grid.InBounds(cell.row, cell.col) || !true_grid.IsFree(cell)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "battery.station (%.3f, %.3f) is not in a free cell of the true map", st.x, st.y));
    }
  }
  const Grid& drive = retained.area != nullptr ? *retained.area->drive : *retained.plan.grid;
  if (drive.rows() != true_grid.rows() || drive.cols() != true_grid.cols()) {
    return absl::InternalError("the plan's grid and the true grid differ in shape");
  }
  std::vector<uint8_t> candidate(static_cast<size_t>(drive.size()), 0);
  for (int64_t i = 0; i < drive.size(); ++i) {
    candidate[i] = drive.free_flags()[i] && !true_grid.free_flags()[i];
  }
  sim_internal::SimulatedDrive sim(true_map, true_grid, options, std::move(retained),
                                   std::move(candidate), source);
  ASSIGN_OR_RETURN(SimulationResult result, sim.Run());
  result.truth_cleared_px = cleared_px;
  result.truth_used = cleared;
  // Coverage against the true map: its free area inside the swept cells.
  const int64_t true_free = true_map.CountFree();
  double swept_free_px = 0.0;
  for (size_t i = 0; i < sim.swept().size(); ++i) {
    if (sim.swept()[i]) swept_free_px += fractions[i] * frame.px_per_cell * frame.px_per_cell;
  }
  result.covered_free_area_ratio = true_free > 0 ? swept_free_px / true_free : 0.0;
  result.length_in_obstacles_m = sim_internal::LengthInObstacles(true_map, result.driven);
  return result;
}

}  // namespace covplan
