// Redividing a fleet mission while the robots drive: a robot stopped for
// good (breakdown, called away, battery dead) hands what it has left to the
// others; a robot that joins takes a share. What is left is every robot's
// remainder (planner/replan's Remaining: the cells of its current plan still
// to sweep, from its progress); the active robots are planned over it as a
// fleet (PlanFleet with a cover mask), each from where it stands now to its
// own end pose. An obstacle one robot reported (its plan, replanned around
// it, has closed its cells) is closed for every robot: the new plans drive
// only on the cells free in every robot's current plan (a drive mask), and
// the cells left there are counted cut off.
//
//   std::vector<MissionRobot> robots = ...;  // current plans, progress, poses
//   robots[1].active = false;                // robot 1 broke down
//   ASSIGN_OR_RETURN(MissionRedivision r, RedivideMission(engine, source, base, robots, options));
//   r.plan.robots[i] is the new plan of r.robot_ids[i]
//
// Thread-safety: reentrant; thread-safe when the engine is.
#ifndef COVPLAN_PLANNER_FLEET_MISSION_H_
#define COVPLAN_PLANNER_FLEET_MISSION_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/fleet/fleet_request.h"
#include "planner/replan/replanner.h"

namespace covplan {

struct MissionRobot {
  FleetRobot robot;  // id, model (its end pose, speeds), battery
  // Its current plan (with its coverage area); null for a robot joining now.
  std::shared_ptr<const RetainedPlan> plan;
  RobotProgress progress;  // where it is on `plan` (waypoint -1: not started)
  // Where it stands now: the start of its new plan. Unset: the progress's
  // position, else its plan's start (required for a robot without a plan).
  std::optional<Pose2> pose;
  bool active = true;  // false: stopped for good; its remainder goes to the others
};

struct MissionOptions {
  FleetDivision division = FleetDivision::kMakespan;
  double clearance_m = 0.0;
};

struct MissionRedivision {
  FleetPlan plan;                      // the active robots' new plans
  std::vector<std::string> robot_ids;  // robot of plan.robots[i], in the order given
  int64_t remaining_cells = 0;         // cells left to cover over the whole mission
  int64_t handed_over_cells = 0;       // of those, left by robots stopped for good
  int64_t cut_off_cells = 0;           // cells of plans no robot can reach any more
};

// Each new plan continues its robot's account: its stats' mission_covered,
// mission_cut_off and mission_obstructed cells carry what the robot's
// earlier plans swept, lost and found blocked (0 for a joining robot).
// InvalidArgument naming the robot ("robots[2] ('c'): ...") for malformed
// progress, a robot without plan or pose, or no active robot while cells are
// left.
absl::StatusOr<MissionRedivision> RedivideMission(const PlanningEngine& engine,
                                                  const MapSource& source, const PlanRequest& base,
                                                  const std::vector<MissionRobot>& robots,
                                                  const MissionOptions& options);

// A mission's account, from each robot's current plan and progress (robots
// as for RedivideMission; a stopped robot handed its remainder over).
struct RobotAccount {
  int64_t covered_cells = 0;    // swept by it over all its plans so far
  int64_t remaining_cells = 0;  // left on its current plan, reachable (0 once stopped)
  int64_t cut_off_cells = 0;    // of its plans' cells, cut off by obstacles
};
struct MissionAccount {
  std::vector<RobotAccount> robots;  // as given
  int64_t covered_cells = 0;         // sum over the robots
  int64_t remaining_cells = 0;       // distinct cells left on the active robots' plans
  int64_t cut_off_cells = 0;         // sum over the robots
  bool complete = false;             // no reachable cell left on any active robot's plan
};

// InvalidArgument naming the robot for malformed progress.
absl::StatusOr<MissionAccount> AccountMission(const std::vector<MissionRobot>& robots);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_MISSION_H_
