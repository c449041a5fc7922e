#include "planner/sim/fleet_simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/common/status_macros.h"
#include "planner/engine/artifact_cache.h"
#include "planner/engine/site.h"
#include "planner/fleet/fleet_planner.h"
#include "planner/sim/clutter.h"
#include "planner/sim/drive.h"
#include "planner/sim/map_frame.h"
#include "planner/sim/obstacle_crossings.h"
#include "planner/sim/run_setup.h"
#include "planner/tour/grid_paths.h"

namespace covplan {

absl::Status FleetSimulationOptions::Validate() const {
  RETURN_IF_ERROR(fleet.Validate());
  for (size_t i = 0; i < fleet.robots.size(); ++i) {
    if (fleet.robots[i].battery) {
      return absl::InvalidArgumentError(
          absl::StrFormat("fleet.robots[%d].battery: fleet simulations do not take batteries", i));
    }
  }
  SimulationOptions robot_sim = sim;
  robot_sim.plan.robot = fleet.robots[0].robot;
  robot_sim.plan.battery.reset();
  RETURN_IF_ERROR(robot_sim.Validate());
  std::set<std::string> failed;
  for (size_t i = 0; i < failures.size(); ++i) {
    const RobotFailure& f = failures[i];
    const bool known = std::any_of(fleet.robots.begin(), fleet.robots.end(),
                                   [&](const FleetRobot& r) { return r.id == f.robot_id; });
    if (!known) {
      return absl::InvalidArgumentError(
          absl::StrFormat("failures[%d].robot_id: no robot '%s' in the fleet", i, f.robot_id));
    }
    if (!failed.insert(f.robot_id).second) {
      return absl::InvalidArgumentError(
          absl::StrFormat("failures[%d].robot_id: robot '%s' fails twice", i, f.robot_id));
    }
    if (!(f.time_s >= 0.0 && std::isfinite(f.time_s))) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "failures[%d].time_s must be a finite number of seconds >= 0, got %g", i, f.time_s));
    }
  }
  return absl::OkStatus();
}

namespace {

using sim_internal::SimulatedDrive;
using sim_internal::TrueSite;

MapSource SourceOf(std::shared_ptr<const OccupancyMap> map, std::string id) {
  MapSource source;
  source.map_id = std::move(id);
  source.load = [map]() -> absl::StatusOr<SiteMap> {
    SiteMap site;
    site.raster = map;
    return site;
  };
  return source;
}

Pose2 PoseOf(const Waypoint& w) { return {w.x, w.y, w.theta}; }

// One robot of the fleet while the simulation runs.
struct RobotState {
  SimulationOptions options;  // the single-robot knobs with this robot's model
  sim_internal::LocalPlanSource source;
  std::unique_ptr<SimulatedDrive> drive;  // the leg being driven, if any
  FleetLeg leg;                           // its start and plan
  FleetRobotRun run;
  Pose2 where;  // where it stands when not driving
  Pose2 end;    // its end pose in the initial plan
  std::vector<uint8_t> swept, found;
};

class FleetRun {
 public:
  FleetRun(const OccupancyMap& known, const OccupancyMap& truth,
           const FleetSimulationOptions& options)
      : known_(std::make_shared<const OccupancyMap>(known)),
        truth_(truth),
        options_(options),
        registry_(BuiltinPlanners()),
        engine_(&registry_, &cache_, EngineLimits{}) {}

  absl::StatusOr<FleetSimulationResult> Run();

 private:
  absl::Status Setup();
  absl::Status StartLeg(size_t i, const FleetRequest& request, size_t j, const FleetRobotPlan& rp,
                        double at_s, const std::string& map_id);
  void EndLeg(size_t i);
  // Drives every robot to `t_s` (its legs' clocks), ending the legs that finish.
  absl::Status DriveUntil(double t_s);
  absl::Status Fail(const RobotFailure& failure);
  std::vector<uint8_t> Left() const;
  absl::Status Redivide(FleetRedivision* redivision);
  void Measure();

  const std::shared_ptr<const OccupancyMap> known_;
  const OccupancyMap& truth_;
  const FleetSimulationOptions& options_;
  PlannerRegistry registry_;
  LocalArtifactCache cache_;
  PlanningEngine engine_;
  PlanOptions grid_plan_;  // the grid options of every plan
  TrueSite site_;
  std::shared_ptr<const CoverageArea> mission_;  // the known map's coverage area
  std::vector<std::unique_ptr<RobotState>> robots_;
  FleetSimulationResult result_;
};

absl::Status FleetRun::Setup() {
  const FleetRequest& fleet = options_.fleet;
  const MapSource known = SourceOf(known_, "known");
  ASSIGN_OR_RETURN(result_.initial, PlanFleet(engine_, known, fleet));
  ASSIGN_OR_RETURN(mission_, engine_.AreaFor(known, fleet.RobotRequest(0)));
  result_.mission_cells = mission_->cover_cells;
  grid_plan_.robot = fleet.robots[0].robot;
  grid_plan_.min_free_fraction = fleet.base.common.min_free_fraction;
  // Nothing stands where a robot starts or ends (see Simulate).
  std::vector<Point2> clear_at;
  for (const FleetRobotPlan& rp : result_.initial.robots) {
    if (rp.result.plan.path.empty()) continue;
    for (const Waypoint* w : {&rp.result.plan.path.front(), &rp.result.plan.path.back()})
      clear_at.push_back({w->x, w->y});
  }
  ASSIGN_OR_RETURN(site_, sim_internal::MakeTrueSite(*known_, truth_, clear_at, grid_plan_));
  result_.truth_used = site_.cleared;
  const size_t cells = static_cast<size_t>(site_.grid.size());
  for (size_t i = 0; i < fleet.robots.size(); ++i) {
    auto state = std::make_unique<RobotState>();
    state->options = options_.sim;
    state->options.plan = grid_plan_;
    state->options.plan.robot = fleet.robots[i].robot;
    state->run.id = fleet.robots[i].id;
    const CoveragePlan& plan = result_.initial.robots[i].result.plan;
    if (plan.path.empty()) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "fleet.robots[%d] ('%s') has no start pose and was given nothing to cover", i,
          state->run.id));
    }
    state->where = PoseOf(plan.path.front());
    state->end = PoseOf(plan.path.back());
    state->swept.assign(cells, 0);
    state->found.assign(cells, 0);
    robots_.push_back(std::move(state));
  }
  for (size_t i = 0; i < fleet.robots.size(); ++i)
    RETURN_IF_ERROR(StartLeg(i, fleet, i, result_.initial.robots[i], 0.0, "known"));
  return absl::OkStatus();
}

absl::Status FleetRun::StartLeg(size_t i, const FleetRequest& request, size_t j,
                                const FleetRobotPlan& rp, double at_s, const std::string& map_id) {
  RobotState& s = *robots_[i];
  if (rp.idle || rp.result.area == nullptr || rp.result.plan.path.size() < 2) return {};
  RetainedPlan retained;
  retained.plan_id = absl::StrFormat("%s-%d", s.run.id, s.run.legs.size());
  retained.map_id = map_id;
  retained.plan = rp.result.plan;
  retained.request = request.RobotRequest(j);
  retained.area = rp.result.area;
  ASSIGN_OR_RETURN(std::vector<uint8_t> candidate,
                   sim_internal::Candidates(*retained.area->drive, site_.grid));
  s.leg = FleetLeg();
  s.leg.start_s = at_s;
  s.leg.plan = rp.result.plan;
  s.drive = std::make_unique<SimulatedDrive>(site_.map(), site_.grid, s.options,
                                             std::move(retained), std::move(candidate), &s.source);
  return absl::OkStatus();
}

void FleetRun::EndLeg(size_t i) {
  RobotState& s = *robots_[i];
  SimulatedDrive& d = *s.drive;
  s.leg.interrupted = !d.finished();
  const double clock = d.clock_s();
  for (size_t c = 0; c < s.swept.size(); ++c) {
    s.swept[c] |= d.swept()[c];
    s.found[c] |= d.found()[c];
  }
  s.where = d.pose();
  s.leg.run = d.Finish();
  s.leg.end_s = s.leg.start_s + (s.leg.interrupted ? clock : s.leg.run.total_time_s);
  s.run.legs.push_back(std::move(s.leg));
  s.drive.reset();
}

absl::Status FleetRun::DriveUntil(double t_s) {
  for (size_t i = 0; i < robots_.size(); ++i) {
    RobotState& s = *robots_[i];
    if (s.drive == nullptr) continue;
    RETURN_IF_ERROR(s.drive->RunUntil(t_s - s.leg.start_s));
    if (s.drive->finished()) EndLeg(i);
  }
  return absl::OkStatus();
}

// The mission's cells nobody swept and nobody found blocked.
std::vector<uint8_t> FleetRun::Left() const {
  std::vector<uint8_t> left(mission_->cover->free_flags().begin(),
                            mission_->cover->free_flags().end());
  for (const auto& s : robots_) {
    for (size_t c = 0; c < left.size(); ++c) {
      const bool swept = s->swept[c] || (s->drive != nullptr && s->drive->swept()[c]);
      const bool found = s->found[c] || (s->drive != nullptr && s->drive->found()[c]);
      if (swept || found) left[c] = 0;
    }
  }
  return left;
}

absl::Status FleetRun::Fail(const RobotFailure& failure) {
  RETURN_IF_ERROR(DriveUntil(failure.time_s));
  size_t failed = 0;
  while (robots_[failed]->run.id != failure.robot_id) ++failed;
  RobotState& f = *robots_[failed];
  if (f.drive != nullptr) EndLeg(failed);
  f.run.failed = true;
  f.run.failed_at_s = failure.time_s;
  FleetRedivision redivision;
  redivision.time_s = failure.time_s;
  redivision.failed_robot = failure.robot_id;
  redivision.left = Left();
  redivision.left_cells = std::count(redivision.left.begin(), redivision.left.end(), 1);
  for (const auto& s : robots_) {
    if (!s->run.failed) redivision.robots.push_back(s->run.id);
  }
  if (redivision.left_cells > 0 && !redivision.robots.empty()) {
    RETURN_IF_ERROR(Redivide(&redivision));
  } else if (redivision.left_cells == 0) {
    redivision.left.clear();
  }
  result_.redivisions.push_back(std::move(redivision));
  return absl::OkStatus();
}

// Plans what is left among the survivors on the known map with every cell
// found blocked so far drawn in as the true map has it, and sets them off.
// Cells the drawn-in obstacles cut off are left out; when none is left the
// survivors drive on.
absl::Status FleetRun::Redivide(FleetRedivision* redivision) {
  auto updated = std::make_shared<OccupancyMap>(*known_);
  const double half = 0.5 * (site_.grid.cell_size() - known_->resolution());
  for (const auto& s : robots_) {
    for (size_t c = 0; c < s->found.size(); ++c) {
      if (s->found[c] || (s->drive != nullptr && s->drive->found()[c]))
        ClearAround(site_.map(), site_.grid.CellCenter(site_.grid.FromIndex(c)), half,
                    updated.get());
    }
  }
  const std::string map_id = absl::StrFormat("known+found-%d", result_.redivisions.size() + 1);
  const MapSource source = SourceOf(std::move(updated), map_id);
  ASSIGN_OR_RETURN(std::shared_ptr<const CoverageArea> area,
                   engine_.AreaFor(source, options_.fleet.RobotRequest(0)));
  int64_t plannable = 0;
  for (size_t c = 0; c < redivision->left.size(); ++c)
    plannable += redivision->left[c] && area->cover->free_flags()[c];
  if (plannable == 0) return absl::OkStatus();
  FleetRequest request = options_.fleet;
  request.robots.clear();
  request.cover_mask = redivision->left;
  std::vector<size_t> who;
  for (size_t i = 0; i < robots_.size(); ++i) {
    RobotState& s = *robots_[i];
    if (s.run.failed) continue;
    if (s.drive != nullptr) EndLeg(i);  // the survivors stop where they are
    FleetRobot robot = options_.fleet.robots[i];
    robot.robot.start = s.where;
    robot.robot.end = s.end;
    request.robots.push_back(std::move(robot));
    who.push_back(i);
  }
  ASSIGN_OR_RETURN(redivision->plan, PlanFleet(engine_, source, request));
  for (size_t j = 0; j < who.size(); ++j) {
    RETURN_IF_ERROR(
        StartLeg(who[j], request, j, redivision->plan.robots[j], redivision->time_s, map_id));
  }
  return absl::OkStatus();
}

void FleetRun::Measure() {
  FleetSimulationResult& r = result_;
  r.swept.assign(static_cast<size_t>(site_.grid.size()), 0);
  for (const auto& s : robots_) {
    FleetRobotRun& run = s->run;
    for (size_t k = 0; k < run.legs.size(); ++k) {
      const SimulationResult& leg = run.legs[k].run;
      run.driven.insert(run.driven.end(), leg.driven.begin() + (k > 0 ? 1 : 0), leg.driven.end());
      run.num_replans += leg.num_replans;
      run.stoppage_s += leg.stoppage_s;
      run.finish_s = run.legs[k].end_s;
      r.completed &= leg.completed;
      for (const std::string& p : leg.problems) r.problems.push_back(run.id + ": " + p);
    }
    run.swept = s->swept;
    run.swept_cells = std::count(s->swept.begin(), s->swept.end(), 1);
    run.length_in_obstacles_m = sim_internal::LengthInObstacles(site_.map(), run.driven);
    r.length_in_obstacles_m += run.length_in_obstacles_m;
    r.makespan_s = std::max(r.makespan_s, run.finish_s);
    for (size_t c = 0; c < r.swept.size(); ++c) r.swept[c] |= s->swept[c];
  }
  for (FleetRedivision& d : r.redivisions) {
    double last = d.time_s;
    for (const auto& s : robots_) {
      if (std::count(d.robots.begin(), d.robots.end(), s->run.id) > 0)
        last = std::max(last, s->run.finish_s);
    }
    d.achieved_s = last - d.time_s;
  }
  r.swept_cells = std::count(r.swept.begin(), r.swept.end(), 1);
  r.covered_free_area_ratio = sim_internal::CoveredFreeAreaRatio(site_, r.swept);
  // Reachable: the mission's cells free on the true grid, in a component
  // that holds a robot's start, as the robots' cell model moves: the true
  // grid's free cells with the known map's walls (new obstacles are blocked
  // cells to it, whatever they touch), less the cells a robot reported for
  // furniture smaller than the cell (a redivision draws that furniture into
  // the known map, where the grid keeps the cell free with barriers, so the
  // survivors may still sweep it; it is not counted as owed).
  std::vector<Point2> starts;
  for (const FleetRobotPlan& rp : r.initial.robots) {
    if (rp.result.plan.path.empty()) continue;
    starts.push_back({rp.result.plan.path.front().x, rp.result.plan.path.front().y});
  }
  std::vector<uint8_t> closed(r.swept.size(), 0);
  for (const auto& s : robots_) {
    for (const FleetLeg& leg : s->run.legs) {
      for (const CellIndex& c : leg.run.obstacles_found) closed[site_.grid.Index(c.row, c.col)] = 1;
    }
  }
  const Grid model = sim_internal::ReachableModel(site_, *mission_->drive, starts);
  const Grid cells = sim_internal::ReachableModel(site_, *mission_->drive, starts, &closed);
  for (size_t c = 0; c < cells.free_flags().size(); ++c) {
    if (!mission_->cover->free_flags()[c] || !cells.free_flags()[c]) continue;
    ++r.reachable_cells;
    if (r.swept[c]) continue;
    ++r.unswept_reachable_cells;
    r.unswept_reachable.push_back(site_.grid.FromIndex(static_cast<int64_t>(c)));
  }
  std::vector<const std::vector<Waypoint>*> paths;
  for (const auto& s : robots_) paths.push_back(&s->run.driven);
  r.floor = sim_internal::DrivenFloor(site_, model, mission_->zones.no_go.get(),
                                      mission_->zones.regions.get(), paths);
  for (const auto& s : robots_) r.robots.push_back(std::move(s->run));
}

absl::StatusOr<FleetSimulationResult> FleetRun::Run() {
  RETURN_IF_ERROR(Setup());
  std::vector<RobotFailure> failures = options_.failures;
  std::stable_sort(
      failures.begin(), failures.end(),
      [](const RobotFailure& a, const RobotFailure& b) { return a.time_s < b.time_s; });
  for (const RobotFailure& f : failures) RETURN_IF_ERROR(Fail(f));
  RETURN_IF_ERROR(DriveUntil(std::numeric_limits<double>::infinity()));
  Measure();
  return std::move(result_);
}

}  // namespace

absl::StatusOr<FleetSimulationResult> SimulateFleet(const OccupancyMap& known,
                                                    const OccupancyMap& truth,
                                                    const FleetSimulationOptions& options) {
  RETURN_IF_ERROR(options.Validate());
  RETURN_IF_ERROR(sim_internal::CheckSameFrame(known, truth));
  FleetRun run(known, truth, options);
  return run.Run();
}

}  // namespace covplan
