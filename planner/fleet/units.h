// The units a fleet divides: the coverage work of one good single-robot tour
// of the whole site, in tour order. A unit is a maximal run of consecutive
// coverage segments with the same tag (Waypoint::rank: an OARP rank, a
// boustrophedon cell, an STC coarse cell), with the cells it sweeps, where it
// is entered and left, and the tour's time from unit to unit. UnitCosts
// prices a piece of consecutive units for one robot: the trip from its start
// to the piece, the piece as the tour drives it (re-timed with the robot's
// own model) and the trip to its end pose.
//
//   ASSIGN_OR_RETURN(TourUnits units, UnitsOfPlan(reference, *area.drive));
//   ASSIGN_OR_RETURN(UnitCosts costs, UnitCosts::Build(units, *area.drive, robots, stop, 2));
//   double t = costs.Piece(r, first, last);
//
// Thread-safety: immutable after construction.
#ifndef COVPLAN_PLANNER_FLEET_UNITS_H_
#define COVPLAN_PLANNER_FLEET_UNITS_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/fleet/fleet_request.h"
#include "planner/grid/grid.h"
#include "planner/plan/coverage_plan.h"

namespace covplan {

struct TourUnit {
  std::vector<int64_t> cells;  // grid indices (Grid::Index), each once
  int entry_waypoint = 0;      // the path index the unit's first sweep starts from
  int exit_waypoint = 0;       // the path index of its last sweep
  Point2 entry, exit;
  double entry_heading = 0.0, exit_heading = 0.0;
};

struct TourUnits {
  std::vector<TourUnit> units;  // in tour order
  std::vector<Waypoint> path;   // the reference tour's path
  int64_t cells = 0;            // distinct cells over all units
};

// The units of `plan` (a plan of the whole cover grid, swept cells on
// `grid`). A cell swept by two units belongs to the first.
TourUnits UnitsOfPlan(const CoveragePlan& plan, const Grid& grid);

class UnitCosts {
 public:
  // Any-angle distance fields on `drive` from each robot's start and end
  // pose, up to `num_threads` searches at a time (InvalidArgument naming
  // robots[i].robot.start/end when a pose lies outside the drive grid or
  // where it cannot join it).
  static absl::StatusOr<UnitCosts> Build(const TourUnits& units, const Grid& drive,
                                         const std::vector<FleetRobot>& robots,
                                         const StopToken& stop, int num_threads = 1);

  int num_robots() const { return static_cast<int>(reach_.size()); }
  int num_units() const { return num_units_; }
  // Pieces run over the tour as a cycle: unit indices m in [0, 2n) stand for
  // unit m mod n, so a piece may wrap from the last unit to the first (the
  // move back from the last unit to the first is priced by straight line).
  // Seconds robot r needs for units first..last (inclusive, first <= last <
  // first + n), from its start and back to its end pose, times scale(r).
  double Piece(int r, int first, int last) const {
    return scale_[r] *
           (reach_[r][first % num_units_] + Along(r, first, last) + ret_[r][last % num_units_]);
  }
  double Reach(int r, int unit) const { return reach_[r][unit % num_units_]; }
  double Return(int r, int unit) const { return ret_[r][unit % num_units_]; }
  // The piece as the tour drives it: its units and the moves between them.
  double Along(int r, int first, int last) const {
    return prefix_[r][last + 1] - prefix_[r][first] - move_[r][last % num_units_];
  }
  // Robot r's seconds on unit m of the tour and the move on to the next
  // (unscaled).
  double Step(int r, int m) const { return prefix_[r][m + 1] - prefix_[r][m]; }
  // Multiplies robot r's piece costs, to learn from its real plans.
  void SetScale(int r, double s) { scale_[r] = s; }
  double scale(int r) const { return scale_[r]; }

 private:
  int num_units_ = 0;
  std::vector<std::vector<double>> reach_;   // [robot][unit]: start -> unit entry
  std::vector<std::vector<double>> ret_;     // [robot][unit]: unit exit -> end
  std::vector<std::vector<double>> move_;    // [robot][unit]: unit exit -> next unit's entry
  std::vector<std::vector<double>> prefix_;  // [robot][m]: units and moves before m in [0, 2n]
  std::vector<double> scale_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_UNITS_H_
