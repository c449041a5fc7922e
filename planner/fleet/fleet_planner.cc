#include "planner/fleet/fleet_planner.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/fleet/bounds.h"
#include "planner/fleet/division.h"
#include "planner/fleet/safety.h"
#include "planner/fleet/units.h"

namespace covplan {
namespace {

// Share of the budget the reference tour of the whole site gets.
constexpr double kReferenceShare = 0.3;
// Rebalancing rounds at most (each plans every robot whose piece changed).
constexpr int kMaxRounds = 6;

double RobotDuration(const FleetRobot& robot, const CoveragePlan& plan) {
  const int64_t cycles = static_cast<int64_t>(plan.cycles.size());
  return plan.stats.estimated_duration_s +
         robot.recharge_s * static_cast<double>(std::max<int64_t>(0, cycles - 1));
}

absl::Status RobotError(const FleetRequest& request, size_t i, const absl::Status& s) {
  return absl::Status(
      s.code(), absl::StrFormat("robots[%d] ('%s'): %s", i, request.robots[i].id, s.message()));
}

// The plan of a robot given nothing: it stays where it starts.
CoveragePlan IdlePlan(const FleetRobot& robot, const CoverageArea& area) {
  CoveragePlan plan;
  plan.grid = area.drive;
  if (robot.robot.start) {
    const Pose2& s = *robot.robot.start;
    plan.path.push_back({s.x, s.y, s.theta, SegmentKind::kStart, -1});
  }
  plan.termination = Termination::Converged("nothing to cover");
  plan.stats.grid_rows = area.drive->rows();
  plan.stats.grid_cols = area.drive->cols();
  return plan;
}

struct RobotJob {
  size_t robot = 0;
  std::vector<uint8_t> mask;
};

// Plans each robot's share, up to `threads` at a time, with `limit_s` each.
absl::Status PlanShares(const PlanningEngine& engine, const MapSource& source,
                        const FleetRequest& request, const CoverageArea& area,
                        const std::vector<std::vector<int64_t>>& cells, double limit_s,
                        FleetPlan* out) {
  const size_t k = request.robots.size();
  out->robots.resize(k);
  std::vector<absl::Status> status(k);
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < k;) {
      FleetRobotPlan& rp = out->robots[i];
      rp.id = request.robots[i].id;
      rp.assigned_cells = static_cast<int64_t>(cells[i].size());
      if (cells[i].empty()) {
        rp.idle = true;
        rp.result = EngineResult{IdlePlan(request.robots[i], area), nullptr, nullptr};
        continue;
      }
      rp.idle = false;
      std::vector<uint8_t> mask(static_cast<size_t>(area.cover->size()), 0);
      for (int64_t c : cells[i]) mask[c] = 1;
      PlanRequest r = request.RobotRequest(i);
      r.common.time_limit_s = limit_s;
      r.common.num_threads = 1;
      absl::StatusOr<EngineResult> result = engine.PlanPart(source, r, mask, request.drive_mask);
      if (!result.ok()) {
        status[i] = RobotError(request, i, result.status());
        continue;
      }
      rp.result = *std::move(result);
    }
  };
  const int threads = std::clamp<int>(request.base.common.num_threads, 1, static_cast<int>(k));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const absl::Status& s : status) RETURN_IF_ERROR(s);
  return absl::OkStatus();
}

double Seconds(absl::Time since) { return absl::ToDoubleSeconds(absl::Now() - since); }

// The division and its improvement on real plans, within the budget. A
// round (planning every robot's share) is started only when the last one
// would still fit in what is left of the budget.
struct FleetSearch {
  const PlanningEngine& engine;
  const MapSource& source;
  const FleetRequest& request;
  std::shared_ptr<const CoverageArea> area;
  const TourUnits& units;
  UnitCosts costs;
  bool connected;  // STC: each robot's region connected
  absl::Time t0;
  bool time_left = true;
  double last_round_s = 0.0;

  double budget() const { return request.base.common.time_limit_s; }
  bool RoundFits() {
    time_left = Seconds(t0) + last_round_s < budget() && !request.base.common.stop.ShouldStop();
    return time_left;
  }
  // The tour search limit of each share when `share` of what is left of
  // the budget goes to the tour searches of a round.
  double ShareLimit(double share) const {
    const size_t k = request.robots.size();
    const int threads = std::clamp<int>(request.base.common.num_threads, 1, static_cast<int>(k));
    const double batches = std::ceil(static_cast<double>(k) / threads);
    return std::max(0.05, (budget() - Seconds(t0)) * share / batches);
  }
  // Plans a division's shares, each share's tour search within `limit`.
  absl::Status PlanDivision(std::vector<std::vector<int64_t>> cells, double limit, FleetPlan* out) {
    if (connected) MakeRegionsConnected(*area->drive, &cells);
    const absl::Time start = absl::Now();
    out->division = request.division;
    RETURN_IF_ERROR(PlanShares(engine, source, request, *area, cells, limit, out));
    FillFleetFigures(request, area->cover_cells, out);
    last_round_s = Seconds(start);
    return absl::OkStatus();
  }
  std::vector<std::optional<Pose2>> Starts() const {
    std::vector<std::optional<Pose2>> starts;
    for (const FleetRobot& r : request.robots) starts.push_back(r.robot.start);
    return starts;
  }
  // Regions grown from the starts that take the reference tour equal time:
  // each cell costs its unit's seconds in the tour (the move on to the next
  // unit included; not the move from the last unit back to the first, which
  // no robot drives) over the unit's cells.
  std::vector<std::vector<int64_t>> TimeRegions() const {
    const Grid& drive = *area->drive;
    std::vector<double> cost(static_cast<size_t>(drive.size()), 0.0);
    double sum = 0.0;
    int64_t cells = 0;
    const int n = costs.num_units();
    for (int u = 0; u < n; ++u) {
      const TourUnit& unit = units.units[u];
      if (unit.cells.empty()) continue;
      const double seconds = u + 1 < n ? costs.Step(0, u) : costs.Along(0, u, u);
      const double each = seconds / static_cast<double>(unit.cells.size());
      for (int64_t c : unit.cells) cost[c] = each;
      sum += seconds;
      cells += static_cast<int64_t>(unit.cells.size());
    }
    // Cells no unit swept (none in a complete tour) and zero-time units:
    // the mean.
    const double mean = cells > 0 && sum > 0.0 ? sum / static_cast<double>(cells) : 1.0;
    for (double& c : cost) {
      if (!(c > 0.0)) c = mean;
    }
    return BalancedRegions(drive, *area->cover, Starts(), cost);
  }

  absl::Status Run(FleetPlan* best) {
    // The first round's limit; the equal-area candidate below gets the same,
    // as the equal-area division planned alone does.
    const double first_limit = ShareLimit(0.5);
    if (request.division == FleetDivision::kEqualArea)
      return PlanDivision(EqualAreaRegions(*area->drive, *area->cover, Starts()), first_limit,
                          best);
    TourSplit split = SplitTour(costs);
    RETURN_IF_ERROR(PlanDivision(CellsOfSplit(units, split), first_limit, best));
    FleetPlan last = *best;  // the plans of `split`
    // Compact regions of equal tour time are one more candidate, where the
    // tour's pieces lie scattered or a robot's trip from its start weighs.
    // It may overrun the budget by 15 % (never the caller's deadline), so
    // that on small sites, where rounds are quick, it is always tried.
    if (!request.base.common.stop.ShouldStop() && Seconds(t0) + last_round_s <= 1.15 * budget()) {
      FleetPlan candidate;
      RETURN_IF_ERROR(PlanDivision(TimeRegions(), first_limit, &candidate));
      if (candidate.makespan_s < best->makespan_s) {
        candidate.from_regions = true;
        *best = std::move(candidate);
      }
    }
    // Rebalance: learn each robot's real cost over the split's estimate
    // (from the last split's own plans) and split again.
    int rounds = 0;
    while (rounds < kMaxRounds && RoundFits()) {
      for (size_t r = 0; r < request.robots.size(); ++r) {
        const auto [a, b] = split.pieces[r];
        if (a > b || last.robots[r].idle) continue;
        const double estimate = costs.Piece(static_cast<int>(r), a, b);
        if (estimate > 0.0 && std::isfinite(estimate))
          costs.SetScale(static_cast<int>(r),
                         costs.scale(static_cast<int>(r)) * last.robots[r].duration_s / estimate);
      }
      TourSplit next = SplitTour(costs);
      if (next.pieces == split.pieces) break;
      split = std::move(next);
      FleetPlan candidate;
      RETURN_IF_ERROR(PlanDivision(CellsOfSplit(units, split), ShareLimit(0.25), &candidate));
      ++rounds;
      last = candidate;
      if (candidate.makespan_s < best->makespan_s) *best = std::move(candidate);
    }
    best->rebalance_rounds = rounds;
    return absl::OkStatus();
  }
};

}  // namespace

void FillFleetFigures(const FleetRequest& request, int64_t cover_cells, FleetPlan* plan) {
  plan->makespan_s = 0.0;
  plan->sum_duration_s = 0.0;
  plan->cover_cells = cover_cells;
  std::vector<uint8_t> swept;
  std::vector<std::string> ids;
  std::vector<TimedPath> paths;
  for (size_t i = 0; i < plan->robots.size(); ++i) {
    FleetRobotPlan& rp = plan->robots[i];
    const CoveragePlan& p = rp.result.plan;
    rp.duration_s = RobotDuration(request.robots[i], p);
    rp.area_share = cover_cells > 0 ? static_cast<double>(rp.assigned_cells) / cover_cells : 0.0;
    plan->makespan_s = std::max(plan->makespan_s, rp.duration_s);
    plan->sum_duration_s += rp.duration_s;
    if (p.grid != nullptr && swept.empty()) swept.assign(static_cast<size_t>(p.grid->size()), 0);
    for (const CoverageSweep& s : p.sweeps) {
      for (const CellIndex& c : s.cells) {
        if (p.grid != nullptr && p.grid->InBounds(c.row, c.col))
          swept[p.grid->Index(c.row, c.col)] = 1;
      }
    }
    // A robot with no path (idle, placed nowhere) is nowhere on the site.
    if (p.path.empty()) continue;
    ids.push_back(rp.id);
    paths.emplace_back(p.path, request.robots[i].robot, p.cycles, request.robots[i].recharge_s);
  }
  plan->covered_cells = std::count(swept.begin(), swept.end(), 1);
  plan->gap = plan->lower_bound_s > 0.0 ? plan->makespan_s / plan->lower_bound_s - 1.0 : 0.0;
  const double clearance =
      request.clearance_m > 0.0 ? request.clearance_m : request.robots[0].robot.tool_width_m;
  plan->safety = FleetSafetyReport(ids, paths, clearance);
}

namespace {

// The floor the whole site's robots sweep together; nothing for a part.
absl::Status MeasureFleetFloor(const PlanningEngine& engine, const MapSource& source,
                               const FleetRequest& request, FleetPlan* plan) {
  if (!request.cover_mask.empty()) return absl::OkStatus();
  PlanRequest site = request.RobotRequest(0);
  site.common.stop = StopToken();  // cached by the plans above: nothing to cut short
  ASSIGN_OR_RETURN(std::shared_ptr<const FloorArtifact> floor, engine.FloorFor(source, site));
  std::vector<const std::vector<Waypoint>*> paths;
  for (const FleetRobotPlan& rp : plan->robots) paths.push_back(&rp.result.plan.path);
  plan->floor = MeasureFloor(floor->reach, paths, /*keep_missed=*/false);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<FleetPlan> PlanFleet(const PlanningEngine& engine, const MapSource& source,
                                    const FleetRequest& request) {
  const absl::Time t0 = absl::Now();
  RETURN_IF_ERROR(request.Validate());
  const size_t k = request.robots.size();
  const double budget = request.base.common.time_limit_s;
  FleetPlan best;
  best.division = request.division;
  if (k == 1) {
    // A fleet of one is the single-robot plan, exactly.
    absl::StatusOr<EngineResult> one =
        request.cover_mask.empty() ? engine.Plan(source, request.RobotRequest(0))
                                   : engine.PlanPart(source, request.RobotRequest(0),
                                                     request.cover_mask, request.drive_mask);
    if (!one.ok()) return RobotError(request, 0, one.status());
    const TourUnits units = UnitsOfPlan(one->plan, *one->area->cover);
    best.robots.resize(1);
    best.robots[0].id = request.robots[0].id;
    best.robots[0].assigned_cells = one->area->cover_cells;
    best.robots[0].result = *std::move(one);
    best.lower_bound_s =
        MakespanLowerBound(units, request.robots, best.robots[0].result.area->drive.get()).value();
    best.termination = best.robots[0].result.plan.termination;
    FillFleetFigures(request, best.robots[0].assigned_cells, &best);
    // The plan measured its floor on the site's floor artifact already.
    const PlanStats& s = best.robots[0].result.plan.stats;
    if (request.cover_mask.empty() && s.reachable_area_m2 > 0.0) {
      best.floor.reachable_area_m2 = s.reachable_area_m2;
      best.floor.missed_reachable_m2 = s.missed_reachable_m2;
      best.floor.swept_reachable_m2 = s.reachable_area_m2 - s.missed_reachable_m2;
      best.floor.swept_reachable_ratio = s.swept_reachable_ratio;
    } else {
      RETURN_IF_ERROR(MeasureFleetFloor(engine, source, request, &best));
    }
    best.planning_ms = Seconds(t0) * 1e3;
    return best;
  }
  // The reference tour of the whole site: robot 0's model, free start and end.
  PlanRequest ref = request.RobotRequest(0);
  ref.common.robot.start.reset();
  ref.common.robot.end.reset();
  ref.battery.reset();
  ref.common.time_limit_s = budget * kReferenceShare;
  absl::StatusOr<EngineResult> whole =
      request.cover_mask.empty()
          ? engine.Plan(source, ref)
          : engine.PlanPart(source, ref, request.cover_mask, request.drive_mask);
  if (!whole.ok()) return whole.status();
  const std::shared_ptr<const CoverageArea> area = whole->area;
  const TourUnits units = UnitsOfPlan(whole->plan, *area->cover);
  ASSIGN_OR_RETURN(UnitCosts costs,
                   UnitCosts::Build(units, *area->drive, request.robots, request.base.common.stop,
                                    request.base.common.num_threads));
  // The bound needs no plan: it is computed beside the search.
  double lower_bound = 0.0;
  std::thread bound_thread(
      [&] { lower_bound = MakespanLowerBound(units, request.robots, area->drive.get()).value(); });

  FleetSearch search{
      engine, source, request, area, units, std::move(costs), whole->plan.planner == "stc", t0};
  const absl::Status searched = search.Run(&best);
  bound_thread.join();
  RETURN_IF_ERROR(searched);
  best.lower_bound_s = lower_bound;
  best.gap = lower_bound > 0.0 ? best.makespan_s / lower_bound - 1.0 : 0.0;
  best.termination =
      Termination::Converged(absl::StrFormat("%d rebalancing rounds", best.rebalance_rounds));
  for (const FleetRobotPlan& rp : best.robots) {
    if (rp.result.plan.termination.limit_reached()) best.termination = rp.result.plan.termination;
  }
  if (!search.time_left && best.termination.reason == TerminationReason::kConverged) {
    best.termination = Termination::LimitReached(request.base.common.stop.ShouldStop()
                                                     ? TerminationLimit::kDeadline
                                                     : TerminationLimit::kTime,
                                                 "the budget ended the rebalancing");
  }
  RETURN_IF_ERROR(MeasureFleetFloor(engine, source, request, &best));
  best.planning_ms = Seconds(t0) * 1e3;
  return best;
}

}  // namespace covplan
