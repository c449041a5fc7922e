#include "planner/fleet/mission.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/fleet/fleet_planner.h"
#include "planner/tour/grid_paths.h"

namespace covplan {
namespace {

absl::Status RobotError(size_t i, const std::string& id, const absl::Status& s) {
  return absl::Status(s.code(), absl::StrFormat("robots[%d] ('%s'): %s", i, id, s.message()));
}

// Where robot i stands now.
absl::StatusOr<Pose2> PoseOf(size_t i, const MissionRobot& r) {
  if (r.pose.has_value()) return *r.pose;
  if (r.plan != nullptr && r.progress.position.has_value()) {
    return Pose2{r.progress.position->x, r.progress.position->y, 0.0};
  }
  if (r.plan != nullptr && !r.plan->plan.path.empty() && r.progress.waypoint < 0 &&
      !r.progress.distance_m.has_value()) {
    const Waypoint& w = r.plan->plan.path.front();
    return Pose2{w.x, w.y, w.theta};
  }
  return RobotError(i, r.robot.id,
                    absl::InvalidArgumentError("pose: required for a robot without a plan or a "
                                               "reported position"));
}

// What is left of a robot's current plan.
struct Remainder {
  std::vector<uint8_t> left;   // per cover-grid cell: still to sweep, reachable
  int64_t cells = 0;           // of them
  int64_t covered_before = 0;  // swept before the robot's position
  int64_t cut_off = 0;         // cut off (unreachable from where it is)
};

// Robot i's remainder from its progress; none reported: it has not started
// and its plan's every cell is left.
absl::StatusOr<Remainder> RemainderOf(size_t i, const MissionRobot& r) {
  Remainder out;
  if (r.plan->area == nullptr) return out;  // an idle robot's plan: given nothing
  if (r.progress.waypoint < 0 && !r.progress.distance_m.has_value()) {
    const Grid& cover = *r.plan->area->cover;
    out.left.assign(static_cast<size_t>(cover.size()), 0);
    for (const CoverageSweep& s : r.plan->plan.sweeps) {
      for (const CellIndex& c : s.cells) {
        uint8_t& f = out.left[static_cast<size_t>(cover.Index(c.row, c.col))];
        out.cells += f == 0;
        f = 1;
      }
    }
    return out;
  }
  absl::StatusOr<ReplanResult> rest = Remaining(*r.plan, r.progress, Observations{});
  if (!rest.ok()) return RobotError(i, r.robot.id, rest.status());
  const std::vector<uint8_t>& cover = rest->area->cover->free_flags();
  out.left.assign(cover.begin(), cover.end());
  for (uint8_t f : out.left) out.cells += f != 0;
  out.covered_before = rest->stats.covered_cells_before;
  out.cut_off = static_cast<int64_t>(rest->unreachable.size());
  return out;
}

// The cells the active robots may drive on: those free in every robot's
// current plan (a plan replanned around a reported obstacle has closed the
// obstacle's cells, and those it cut off from that robot: an obstacle one
// robot met is closed for all), kept to the component that holds the most
// active robots (ties: the larger component). Empty when no robot has a
// plan yet (the site's own grid).
absl::StatusOr<std::vector<uint8_t>> MissionDrive(const std::vector<MissionRobot>& robots) {
  std::vector<uint8_t> free;
  const Grid* shape = nullptr;
  for (size_t i = 0; i < robots.size(); ++i) {
    const MissionRobot& r = robots[i];
    if (r.plan == nullptr || r.plan->area == nullptr) continue;
    const Grid& d = *r.plan->area->drive;
    if (shape == nullptr) {
      shape = &d;
      free = d.free_flags();
      continue;
    }
    if (d.size() != shape->size()) {
      return RobotError(i, r.robot.id,
                        absl::InvalidArgumentError("its plan is on another grid than the "
                                                   "mission's"));
    }
    for (size_t c = 0; c < free.size(); ++c) free[c] = free[c] && d.free_flags()[c];
  }
  if (shape == nullptr) return free;
  const Grid grid = shape->WithFreeFlags(free);
  int32_t n = 0;
  const std::vector<int32_t> comp = FreeComponents(grid, &n);
  std::vector<std::pair<int64_t, int64_t>> weight(static_cast<size_t>(n), {0, 0});
  for (int32_t id : comp) {
    if (id >= 0) ++weight[static_cast<size_t>(id)].second;
  }
  for (size_t i = 0; i < robots.size(); ++i) {
    if (!robots[i].active) continue;
    ASSIGN_OR_RETURN(Pose2 pose, PoseOf(i, robots[i]));
    absl::StatusOr<CellIndex> cell = JoinCell(grid, pose, "robot");
    if (cell.ok()) ++weight[static_cast<size_t>(comp[grid.Index(cell->row, cell->col)])].first;
  }
  const int32_t keep =
      static_cast<int32_t>(std::max_element(weight.begin(), weight.end()) - weight.begin());
  for (size_t c = 0; c < free.size(); ++c) free[c] = comp[c] == keep;
  return free;
}

}  // namespace

absl::StatusOr<MissionAccount> AccountMission(const std::vector<MissionRobot>& robots) {
  MissionAccount out;
  std::vector<uint8_t> left;
  for (size_t i = 0; i < robots.size(); ++i) {
    const MissionRobot& r = robots[i];
    RobotAccount& a = out.robots.emplace_back();
    if (r.plan == nullptr || r.plan->area == nullptr) continue;  // given nothing
    ASSIGN_OR_RETURN(Remainder rest, RemainderOf(i, r));
    const PlanStats& s = r.plan->plan.stats;
    a.covered_cells = s.mission_covered_cells + rest.covered_before;
    a.cut_off_cells = s.mission_cut_off_cells + rest.cut_off;
    out.covered_cells += a.covered_cells;
    out.cut_off_cells += a.cut_off_cells;
    if (!r.active) continue;  // its remainder was handed over
    a.remaining_cells = rest.cells;
    if (left.size() < rest.left.size()) left.resize(rest.left.size(), 0);
    for (size_t c = 0; c < rest.left.size(); ++c) left[c] |= rest.left[c];
  }
  for (uint8_t f : left) out.remaining_cells += f != 0;
  out.complete = out.remaining_cells == 0;
  return out;
}

absl::StatusOr<MissionRedivision> RedivideMission(const PlanningEngine& engine,
                                                  const MapSource& source, const PlanRequest& base,
                                                  const std::vector<MissionRobot>& robots,
                                                  const MissionOptions& options) {
  MissionRedivision out;
  ASSIGN_OR_RETURN(std::vector<uint8_t> drive, MissionDrive(robots));
  std::vector<uint8_t> left;        // per cell: 1 to cover, 2 closed (counted cut off)
  std::vector<PlanStats> accounts;  // per active robot
  FleetRequest fleet;
  fleet.base = base;
  fleet.division = options.division;
  fleet.clearance_m = options.clearance_m;
  for (size_t i = 0; i < robots.size(); ++i) {
    const MissionRobot& r = robots[i];
    PlanStats carried;  // the robot's account so far, for its new plan
    if (r.plan != nullptr) {
      ASSIGN_OR_RETURN(Remainder rest, RemainderOf(i, r));
      const PlanStats& s = r.plan->plan.stats;
      carried.mission_covered_cells = s.mission_covered_cells + rest.covered_before;
      carried.mission_cut_off_cells = s.mission_cut_off_cells + rest.cut_off;
      carried.mission_obstructed_cells = s.mission_obstructed_cells;
      const std::vector<uint8_t>& cover = rest.left;  // empty: given nothing
      if (left.empty()) left.assign(cover.size(), 0);
      if (!cover.empty() && left.size() != cover.size()) {
        return RobotError(i, r.robot.id,
                          absl::InvalidArgumentError("its plan is on another grid than the "
                                                     "mission's"));
      }
      for (size_t c = 0; c < cover.size(); ++c) {
        if (!cover[c] || left[c]) continue;
        if (!drive.empty() && !drive[c]) {  // closed by an obstacle another robot met
          left[c] = 2;
          ++out.cut_off_cells;
          continue;
        }
        left[c] = 1;
        ++out.remaining_cells;
        out.handed_over_cells += !r.active;
      }
      out.cut_off_cells += rest.cut_off;
    }
    if (!r.active) continue;
    accounts.push_back(carried);
    ASSIGN_OR_RETURN(Pose2 pose, PoseOf(i, r));
    FleetRobot robot = r.robot;
    robot.robot.start = pose;
    fleet.robots.push_back(std::move(robot));
    out.robot_ids.push_back(r.robot.id);
  }
  if (out.remaining_cells == 0) return out;  // nothing left: no plans
  if (fleet.robots.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "robots: %d cells are left to cover and no robot is active", out.remaining_cells));
  }
  for (uint8_t& f : left) f = f == 1;
  fleet.cover_mask = std::move(left);
  fleet.drive_mask = std::move(drive);
  ASSIGN_OR_RETURN(out.plan, PlanFleet(engine, source, fleet));
  for (size_t k = 0; k < out.plan.robots.size() && k < accounts.size(); ++k) {
    PlanStats& s = out.plan.robots[k].result.plan.stats;
    s.mission_covered_cells = accounts[k].mission_covered_cells;
    s.mission_cut_off_cells = accounts[k].mission_cut_off_cells;
    s.mission_obstructed_cells = accounts[k].mission_obstructed_cells;
  }
  return out;
}

}  // namespace covplan
