// Dividing a site's cells among the robots of a fleet.
//
// SplitTour (the makespan division): route first, cluster second. The units
// of one good tour of the whole site (units.h), taken as a cycle, are cut
// into k consecutive pieces, one per robot, so that the largest piece cost (UnitCosts::Piece:
// the trip from the robot's start, the piece as the tour drives it, the trip
// to its end) is as small as the search finds: for each robot order tried,
// and each place the cycle is cut (up to 32: evenly spaced, and the unit
// nearest each robot's start), a binary search on the makespan T with a
// greedy feasibility test (each robot in turn takes the longest run of units
// it finishes within T). Orders: every permutation while k! is small, else
// the robots sorted by where along the tour their start is nearest, improved
// by swapping neighbours at the best cut. Of splits within 1 % of the best
// makespan, the one with the least summed robot time (trips from the starts
// included) is kept: robots stay nearer home. Pieces of a tour that sweeps a
// room before the next are runs of rooms; where the tour comes back (long
// aisles across a warehouse) they scatter, and BalancedRegions is the
// compact alternative.
//
// EqualAreaRegions (the DARP-style baseline): regions of equal cell count,
// grown in turns from each robot's start over the drive grid, each region
// connected; cells no region reached go to the nearest region, and regions
// left uneven (a robot boxed in by the others) trade border cells, largest
// to its smallest neighbour, until the spread stops narrowing.
//
// BalancedRegions: the same with a cost per cell (the makespan division's
// candidate: the seconds the reference tour spends per cell), regions of
// equal summed cost.
//
// MakeRegionsConnected: the cells of each robot that lie outside its
// largest connected part are handed to the neighbouring region that touches
// them most (STC needs a connected region per robot).
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_FLEET_DIVISION_H_
#define COVPLAN_PLANNER_FLEET_DIVISION_H_

#include <cstdint>
#include <optional>
#include <vector>

#include "planner/fleet/units.h"
#include "planner/grid/grid.h"
#include "planner/tour/robot_model.h"

namespace covplan {

struct TourSplit {
  std::vector<int> order;  // robots in tour order
  // Per robot: units [first, last] of the cycle (indices mod n); first > last: none.
  std::vector<std::pair<int, int>> pieces;
  double estimate_s = 0.0;  // the largest piece cost
};

TourSplit SplitTour(const UnitCosts& costs);

// Cells (grid indices) of robot r under `split`.
std::vector<std::vector<int64_t>> CellsOfSplit(const TourUnits& units, const TourSplit& split);

// Per robot, the cover cells of an equal-area region. `starts` holds each
// robot's start pose (nullopt: seeds spread over the site, farthest first).
std::vector<std::vector<int64_t>> EqualAreaRegions(const Grid& drive, const Grid& cover,
                                                   const std::vector<std::optional<Pose2>>& starts);

// Per robot, the cover cells of a region whose cells cost about 1/k of
// all; `cost` is indexed like the grids (Grid::Index), each entry positive
// and finite.
std::vector<std::vector<int64_t>> BalancedRegions(const Grid& drive, const Grid& cover,
                                                  const std::vector<std::optional<Pose2>>& starts,
                                                  const std::vector<double>& cost);

// Rewrites `cells` (per robot) so that each robot's cells are connected on
// `drive` (4-neighbours, barriers respected); returns the cells moved.
int64_t MakeRegionsConnected(const Grid& drive, std::vector<std::vector<int64_t>>* cells);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_DIVISION_H_
