// What every simulated run sets up (internal to planner/sim), for one robot
// (simulator.cc) and for a fleet (fleet_simulator.cc): the true map with
// nothing standing where robots start and end, its grid in the plans' frame,
// the cells a sensor can find, the coverage and the floor measured against
// the true map, and the in-process plan source.
//
//   ASSIGN_OR_RETURN(TrueSite site, MakeTrueSite(known, truth, {start, end}, options.plan));
//   SimulatedDrive drive(site.map(), site.grid, options, plan,
//                        Candidates(drive_grid, site.grid), source.get());
//   CoveredFreeAreaRatio(site, drive.swept());
//
// Thread-safety: plain functions; a LocalPlanSource serves one run at a time.
#ifndef COVPLAN_PLANNER_SIM_RUN_SETUP_H_
#define COVPLAN_PLANNER_SIM_RUN_SETUP_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/floor_measure.h"
#include "planner/sim/simulator.h"

namespace covplan::sim_internal {

// The true map a run drives and its grid (cells of the tool width, the
// plans' frame).
struct TrueSite {
  const OccupancyMap& map() const { return cleared != nullptr ? *cleared : *truth; }
  const OccupancyMap* truth = nullptr;    // as given
  std::shared_ptr<OccupancyMap> cleared;  // truth cleared around the poses; null if unchanged
  int64_t cleared_px = 0;                 // pixels that clearing freed
  GridFrame frame;
  std::vector<double> fractions;  // per cell: free share on map()
  Grid grid;
};

// `truth` taken as `known` within a tool width of each of `clear_at` (where
// robots stand when they start and end: nothing can stand there), and its
// grid with `plan`'s grid options. `known` and `truth` must share a frame.
absl::StatusOr<TrueSite> MakeTrueSite(const OccupancyMap& known, const OccupancyMap& truth,
                                      const std::vector<Point2>& clear_at, const PlanOptions& plan);

// Per cell: free on the plan's drive grid and blocked on the true grid (what
// a sensor can find). Internal when the two grids differ in shape.
absl::StatusOr<std::vector<uint8_t>> Candidates(const Grid& drive, const Grid& true_grid);

// The true map's free area inside the cells flagged in `swept`, over its free area.
double CoveredFreeAreaRatio(const TrueSite& site, const std::vector<uint8_t>& swept);

// The robots' cell model of the true site: the cells free on both `drive`
// (the robots' part of the known map, with its walls) and the true grid,
// and not flagged in `closed` (when given: per cell, reported by a robot for
// an obstacle smaller than the cell), that lie in a component holding one of
// `starts`. What a robot can get to as the replanner moves it (new obstacles
// are blocked cells to it).
Grid ReachableModel(const TrueSite& site, const Grid& drive, const std::vector<Point2>& starts,
                    const std::vector<uint8_t>* closed = nullptr);

// The floor a tool disc can reach on the true map from the free cells of
// `model` (a ReachableModel; floor_measure.h), outside `no_go` and inside
// `regions` (either may be null), and how much of it `paths` swept.
FloorMeasure DrivenFloor(const TrueSite& site, const Grid& model, const Area* no_go,
                         const Area* regions,
                         const std::vector<const std::vector<Waypoint>*>& paths);

// Plans (PlanCoverageWithArea) and replans (Replan, with an estimator of its
// own) in process.
class LocalPlanSource final : public PlanSource {
 public:
  absl::StatusOr<RetainedPlan> InitialPlan(const OccupancyMap& known,
                                           const PlanOptions& options) override;
  absl::StatusOr<ReplanResult> Replan(const RetainedPlan& plan, const RobotProgress& at,
                                      const Observations& seen,
                                      const ReplanOptions& options) override;

 private:
  ReplanEstimator estimator_;
};

}  // namespace covplan::sim_internal

#endif  // COVPLAN_PLANNER_SIM_RUN_SETUP_H_
