// Battery inputs and the energy model of battery-constrained tours (BC
// Sweep, Strimel & Veloso): capacity, the service-station pose, a safety
// reserve, and an energy model that is linear in the path (per metre, per
// turn, per second of driving/turning under the robot's time model; the
// default is energy = distance in metres). PathEnergy is the one place a
// path's energy is computed, so the split (charge_split.h), the reported
// cycle energies and the tests agree by construction.
//
//   BatteryOptions b; b.capacity = 400; b.station = {1.0, 1.0, 0.0}; b.reserve = 20;
//   RETURN_IF_ERROR(b.Validate());
//   double e = PathEnergy(plan.path, 0, plan.path.size() - 1, b.energy, robot);
//
// Thread-safety: plain value types and stateless functions.
#ifndef COVPLAN_PLANNER_ENERGY_BATTERY_H_
#define COVPLAN_PLANNER_ENERGY_BATTERY_H_

#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

struct EnergyModel {
  double per_metre = 1.0;         // per metre driven
  double per_turn = 0.0;          // per heading change (> 1e-6 rad), as PlanStats counts turns
  double per_second = 0.0;        // per second of driving and turning (robot time model)
  absl::Status Validate() const;  // names "battery.energy.*"
};

struct BatteryOptions {
  double capacity = 0.0;  // energy units of a full charge
  Pose2 station;          // where every charge cycle starts and ends
  double reserve = 0.0;   // never planned below this
  EnergyModel energy;
  // false: a unit (an OARP rank, a boustrophedon cell, ...) is atomic, never
  // interrupted by a charge. true: units may be left after any of their
  // coverage lines and resumed there.
  bool interruptible_units = false;
  // With interruptible_units: the tags (Waypoint::rank: cell or rank ids) of
  // the units that stay atomic anyway (the paper's set A; the rest is B).
  std::vector<int> atomic_units;
  bool IsAtomic(int tag) const;

  double budget() const { return capacity - reserve; }
  // InvalidArgument naming the field ("battery.capacity: ...") for values
  // that are not finite, a non-positive capacity, a negative reserve or one
  // not below the capacity. The station is checked against the map by
  // SplitIntoChargeCycles.
  absl::Status Validate() const;
};

// Energy of the segment ending at `b`, driven after a segment whose heading
// was `heading_before` (the turn onto b.theta is part of it).
double SegmentEnergy(double heading_before, const Waypoint& a, const Waypoint& b,
                     const EnergyModel& model, const RobotModel& robot);
// Energy of driving path[lo] .. path[hi] (the robot at path[lo] heading
// path[lo].theta).
double PathEnergy(const std::vector<Waypoint>& path, size_t lo, size_t hi, const EnergyModel& model,
                  const RobotModel& robot);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENERGY_BATTERY_H_
