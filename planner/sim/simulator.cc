#include "planner/sim/simulator.h"

#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/geometry/area.h"
#include "planner/grid/grid.h"
#include "planner/sim/clutter.h"
#include "planner/sim/drive.h"
#include "planner/sim/map_frame.h"
#include "planner/sim/obstacle_crossings.h"
#include "planner/sim/run_setup.h"

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

absl::StatusOr<SimulationResult> Simulate(const OccupancyMap& known, const OccupancyMap& truth,
                                          const SimulationOptions& options, PlanSource* source) {
  RETURN_IF_ERROR(options.Validate());
  RETURN_IF_ERROR(sim_internal::CheckSameFrame(known, truth));
  sim_internal::LocalPlanSource local;
  if (source == nullptr) source = &local;
  ASSIGN_OR_RETURN(RetainedPlan retained, source->InitialPlan(known, options.plan));
  if (retained.plan.grid == nullptr || retained.plan.path.empty()) {
    return absl::InternalError("the initial plan has no grid or no path");
  }
  // Nothing stands where the robot starts or on its dock (the end pose).
  // Battery runs start and end at the station, which the true map itself
  // must leave free (checked below; the CLI keeps its clutter off it).
  std::vector<Point2> clear_at;
  if (!options.plan.battery) {
    for (const Waypoint* w : {&retained.plan.path.front(), &retained.plan.path.back()})
      clear_at.push_back({w->x, w->y});
  }
  ASSIGN_OR_RETURN(sim_internal::TrueSite site,
                   sim_internal::MakeTrueSite(known, truth, clear_at, options.plan));
  const Grid& true_grid = site.grid;
  if (options.plan.battery) {
    // The robot must be able to dock: nothing the sensor could find there.
    const Pose2& st = options.plan.battery->station;
    const CellIndex cell = true_grid.CellAt({st.x, st.y});
    if (!true_grid.InBounds(cell.row, cell.col) || !true_grid.IsFree(cell)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "battery.station (%.3f, %.3f) is not in a free cell of the true map", st.x, st.y));
    }
  }
  // Held here: the run replaces its plan (and with it the area) on replans.
  const std::shared_ptr<const Grid> drive =
      retained.area != nullptr ? retained.area->drive : retained.plan.grid;
  ASSIGN_OR_RETURN(std::vector<uint8_t> candidate, sim_internal::Candidates(*drive, true_grid));
  sim_internal::SimulatedDrive sim(site.map(), true_grid, options, std::move(retained),
                                   std::move(candidate), source);
  ASSIGN_OR_RETURN(SimulationResult result, sim.Run());
  result.truth_cleared_px = site.cleared_px;
  result.truth_used = site.cleared;
  // Coverage against the true map: its free area inside the swept cells.
  result.covered_free_area_ratio = sim_internal::CoveredFreeAreaRatio(site, sim.swept());
  result.length_in_obstacles_m = sim_internal::LengthInObstacles(site.map(), result.driven);
  // The floor against the true map (the zones were checked by the plan).
  ASSIGN_OR_RETURN(const Area no_go, Area::Create(options.plan.no_go, "no_go"));
  ASSIGN_OR_RETURN(const Area regions, Area::Create(options.plan.regions, "regions"));
  const Point2 start{result.driven.front().x, result.driven.front().y};
  result.floor =
      sim_internal::DrivenFloor(site, sim_internal::ReachableModel(site, *drive, {start}), &no_go,
                                &regions, {&result.driven});
  return result;
}

}  // namespace covplan
