// What is left to cover (internal to planner/replan): from the old plan, where
// the robot is on it and the obstacles it reported, the state every replanning
// method starts from: the old path still ahead as legs, the new drive grid
// (the old one less the new obstacles, cut to the robot's component), the
// cells still to sweep on it, and the end pose (moved to the nearest reachable
// cell when the new obstacles block or cut off the old one).
//
//   ReplanResult out;
//   ASSIGN_OR_RETURN(const Remainder rest, ComputeRemainder(old, progress, seen, &out));
//   rest.to_cover  // per cell: still to sweep and reachable
//
// Thread-safety: ComputeRemainder is reentrant; a Remainder is not changed
// after it is built and may be read from several threads.
#ifndef COVPLAN_PLANNER_REPLAN_REMAINDER_H_
#define COVPLAN_PLANNER_REPLAN_REMAINDER_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/engine/engine.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/replan/replan_walk.h"
#include "planner/replan/replanner.h"
#include "planner/tour/robot_model.h"

namespace covplan::replan_internal {

struct Remainder {
  const RetainedPlan* old = nullptr;
  const OarpDetail* old_oarp = nullptr;  // the old plan's ranks; null for other planners
  RobotModel robot;
  Located at;             // the robot on the old path
  std::vector<Leg> legs;  // the old path from the robot on
  // The old drive grid less the new obstacles, the robot's component.
  std::shared_ptr<const Grid> drive;
  std::vector<uint8_t> to_cover;  // per cell: still to sweep and reachable
  Pose2 end;                      // where the new plan ends
};

// Fills `out`'s area (drive and cover grids of the remainder), unreachable
// cells and the stats that describe the remainder (newly blocked, covered
// before, remaining, cut off, obstructed cells; robot cell and end moves).
// `old` must have its coverage area. InvalidArgument for malformed progress or
// observations, and when the robot is neither in nor next to a free cell.
absl::StatusOr<Remainder> ComputeRemainder(const RetainedPlan& old, const RobotProgress& progress,
                                           const Observations& observations, ReplanResult* out);

}  // namespace covplan::replan_internal

#endif  // COVPLAN_PLANNER_REPLAN_REMAINDER_H_
