// A lower bound on the makespan of a fleet plan (docs/fleet.md gives the
// proof). It holds for every fleet plan that sweeps the reference tour's
// units (units.h) as that tour drives each of them, forwards or backwards,
// with the robots' own models (trapezoidal straight moves, turns in place):
//
//   work:  makespan >= (sum over units of [the fastest robot's time to drive
//          the unit + the cheapest way into it from another unit's exit or a
//          start]) / k. "The cheapest way in" from pose a to pose b is
//          StraightTime(L(a, b)) at the fleet's top speed and acceleration (a
//          path's straight moves from rest to rest take at least one move of
//          their summed length, StraightTime being concave) plus TurnBound
//          at its top turn rate: the least turning of any path from a's
//          heading to b's, at least the net change and, when the robot moves,
//          the way through the direction of b - a or else a full turn less
//          the net change; raised by the detour a blocked cell or a wall on
//          the segment ab forces (detour_turn.h). At most k units are entered
//          from a start, so the k largest savings of a start over a unit are
//          taken off; when the fleet is small, the largest of a matching, an
//          assignment and a Held-Karp 1-tree relaxation of the moves
//          (one_tree.h) is used instead;
//   reach: makespan >= max over units of min over robots of (the move from
//          the robot's start to the unit + the unit + the move to its end
//          pose), for the unit's better direction.
//
// L(a, b), the least length of a path from a to b, is the straight line |ab|
// or, given the drive grid the plans' paths stay on, the longer of |ab| and
// the geodesic bound of geodesic.h (walls between a and b).
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_FLEET_BOUNDS_H_
#define COVPLAN_PLANNER_FLEET_BOUNDS_H_

#include <vector>

#include "planner/fleet/fleet_request.h"
#include "planner/fleet/units.h"
#include "planner/grid/grid.h"

namespace covplan {

struct MakespanBound {
  double work_s = 0.0;
  double reach_s = 0.0;
  double value() const { return work_s > reach_s ? work_s : reach_s; }
};

// `drive`: the grid whose free cells every path of the fleet's plans stays on
// (a start or end pose may stand in a blocked cell beside them); null prices
// moves by straight lines only.
MakespanBound MakespanLowerBound(const TourUnits& units, const std::vector<FleetRobot>& robots,
                                 const Grid* drive);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_BOUNDS_H_
