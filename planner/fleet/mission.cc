#include "planner/fleet/mission.h"

#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/fleet/fleet_planner.h"

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

}  // namespace

absl::StatusOr<MissionRedivision> RedivideMission(const PlanningEngine& engine,
                                                  const MapSource& source, const PlanRequest& base,
                                                  const std::vector<MissionRobot>& robots,
                                                  const MissionOptions& options) {
  MissionRedivision out;
  std::vector<uint8_t> left;
  FleetRequest fleet;
  fleet.base = base;
  fleet.division = options.division;
  fleet.clearance_m = options.clearance_m;
  for (size_t i = 0; i < robots.size(); ++i) {
    const MissionRobot& r = robots[i];
    if (r.plan != nullptr) {
      // No progress reported: it has not started, everything is left.
      RobotProgress progress = r.progress;
      if (progress.waypoint < 0 && !progress.distance_m.has_value()) progress.distance_m = 0.0;
      absl::StatusOr<ReplanResult> rest = Remaining(*r.plan, progress, Observations{});
      if (!rest.ok()) return RobotError(i, r.robot.id, rest.status());
      const std::vector<uint8_t>& cover = rest->area->cover->free_flags();
      if (left.empty()) left.assign(cover.size(), 0);
      if (left.size() != cover.size()) {
        return RobotError(i, r.robot.id,
                          absl::InvalidArgumentError("its plan is on another grid than the "
                                                     "mission's"));
      }
      for (size_t c = 0; c < cover.size(); ++c) {
        if (!cover[c] || left[c]) continue;
        left[c] = 1;
        ++out.remaining_cells;
        out.handed_over_cells += !r.active;
      }
      out.cut_off_cells += static_cast<int64_t>(rest->unreachable.size());
    }
    if (!r.active) continue;
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
  fleet.cover_mask = std::move(left);
  ASSIGN_OR_RETURN(out.plan, PlanFleet(engine, source, fleet));
  return out;
}

}  // namespace covplan
