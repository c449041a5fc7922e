// Battery-constrained tours for every planner (BC Sweep on the planner-
// neutral CoveragePlan). The plan's coverage segments are grouped into units
// by their tag (Waypoint::rank: an OARP rank, a boustrophedon cell; an
// untagged segment is a unit of its own), in path order. Atomic units are
// pieces (all units, or with interruptible_units those in atomic_units);
// interruptible units are cut after each of their coverage lines,
// and a cycle that leaves after line k returns to that very point. The
// pieces are split optimally for the plan's order (charge_split.h); every
// cycle starts and ends at the station, with kFromStation / kToStation legs
// driven as any-angle paths on the drive grid.
//
//   ASSIGN_OR_RETURN(CoveragePlan split, SplitIntoChargeCycles(plan, *area.drive, battery, robot,
//   stop)); for (const ChargeCycle& c : split.cycles) { split.path[c.leave_waypoint] ... }
//
// stats.energy_lower_bound bounds every split of this tour order from below:
// E_u is the unconstrained energy of the tour from the station and back, and
// a station visit after piece k costs delta_k more (return leg + outbound
// leg - the tour's own move it replaces; negative when that move is longer
// than the way through the station, as STC's walk can be). A split costs at
// least E_u + every negative delta, so it makes at least
// c = ceil((E_u + negatives) / budget) - 1 visits; the bound is E_u + the
// negative deltas + the smallest remaining deltas up to c visits.
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_ENERGY_CHARGE_CYCLES_H_
#define COVPLAN_PLANNER_ENERGY_CHARGE_CYCLES_H_

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/energy/battery.h"
#include "planner/grid/grid.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

// InvalidArgument when the station lies outside `drive`'s extent, in an
// obstacle or a closed cell, or cannot reach some unit, or when a unit (or,
// interruptible, one line) cannot be reached, done and returned from within
// budget() (the message names the unit and the energy it needs).
absl::Status CheckStation(const Grid& drive, const BatteryOptions& battery);
absl::StatusOr<CoveragePlan> SplitIntoChargeCycles(const CoveragePlan& plan, const Grid& drive,
                                                   const BatteryOptions& battery,
                                                   const RobotModel& robot, const StopToken& stop);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENERGY_CHARGE_CYCLES_H_
