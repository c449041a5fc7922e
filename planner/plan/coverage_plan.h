// The result every coverage planner produces, whatever its method: the path
// (waypoints with headings and segment kinds), the cells each coverage
// segment sweeps (so coverage is proven from the path, not from ranks),
// statistics every planner fills, how the search ended (Termination), and a
// planner-specific detail beside them (ranks and their order for OARP).
//
//   const CoveragePlan& plan = ...;
//   for (const CoverageSweep& s : plan.sweeps) { plan.path[s.waypoint] ... s.cells ... }
//   if (auto* oarp = plan.detail_as<OarpDetail>()) { oarp->ranks ... }
//
// Thread-safety: plain value types; `detail` is immutable and shared.
#ifndef COVPLAN_PLANNER_PLAN_COVERAGE_PLAN_H_
#define COVPLAN_PLANNER_PLAN_COVERAGE_PLAN_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "planner/grid/grid.h"

namespace covplan {

enum class SegmentKind : uint8_t {
  kStart = 0,        // first waypoint; no segment ends here
  kCoverage = 1,     // the straight segment ending here sweeps new cells
  kTransition = 2,   // the segment ending here moves without sweeping new cells
  kToStation = 3,    // drives to a service station (battery-split tours)
  kFromStation = 4,  // drives back from a service station to resume
};

struct Waypoint {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;  // heading while driving the segment that ends here (rad)
  SegmentKind kind = SegmentKind::kStart;
  // The planner's own index of what the segment serves (the rank for OARP
  // coverage segments), else -1.
  int rank = -1;
};

// The cells swept by the coverage segment that ends at path[waypoint].
struct CoverageSweep {
  int waypoint = 0;
  std::vector<CellIndex> cells;
};

// How a search ended (in the spirit of OR-tools math_opt's Termination).
enum class TerminationReason : uint8_t {
  kConverged = 0,             // the search stopped by itself
  kFeasibleLimitReached = 1,  // a limit stopped it; the plan is feasible (best found)
};
enum class TerminationLimit : uint8_t {
  kNone = 0,       // with kConverged
  kTime = 1,       // the request's own time limit (time_limit_s)
  kDeadline = 2,   // the caller's deadline
  kCancelled = 3,  // the caller cancelled
};
struct Termination {
  TerminationReason reason = TerminationReason::kConverged;
  TerminationLimit limit = TerminationLimit::kNone;
  std::string detail;
  bool limit_reached() const { return reason == TerminationReason::kFeasibleLimitReached; }
  static Termination Converged(std::string detail = "") {
    return {TerminationReason::kConverged, TerminationLimit::kNone, std::move(detail)};
  }
  static Termination LimitReached(TerminationLimit limit, std::string detail = "") {
    return {TerminationReason::kFeasibleLimitReached, limit, std::move(detail)};
  }
};
const char* TerminationReasonName(TerminationReason r);
const char* TerminationLimitName(TerminationLimit l);

// Where a plan came from (planner/engine/plan_memory.h).
enum class PlanOrigin : uint8_t {
  kCold = 0,       // searched from scratch (no remembered tour)
  kCacheHit = 1,   // the remembered plan of an identical request, no search
  kImproved = 2,   // an identical request's remembered tour, searched further
  kWarmStart = 3,  // searched from the remembered tour of a request that differed in start/end/seed
};
const char* PlanOriginName(PlanOrigin s);  // "cold", "cache_hit", "improved", "warm_start"

// Statistics every planner fills (the engine computes the path-derived ones
// from the waypoints, so they agree with the path by construction).
struct PlanStats {
  int64_t num_ranks = 0;  // OARP: ranks; other planners: coverage segments
  int64_t num_turns = 0;  // heading changes > 1e-6 rad along the path
  double coverage_length_m = 0.0;
  double transition_length_m = 0.0;
  double covered_free_area_ratio = 0.0;
  double estimated_duration_s = 0.0;  // coverage + transition driving + turning
  double turning_time_s = 0.0;
  int64_t grid_rows = 0;
  int64_t grid_cols = 0;
  int64_t free_cells = 0;              // cells to cover (in the regions, when given)
  int64_t covered_cells = 0;           // distinct cells swept by the path
  int64_t unreachable_free_cells = 0;  // cells to cover that the robot cannot reach
  int64_t no_go_cells = 0;             // free cells closed by no-go zones
  // Replanned plans continue a mission: the cells its earlier plans swept
  // before this one started, those new obstacles cut off, and those new
  // obstacles now occupy (0 for a first plan). free_cells + these three =
  // the mission's cells.
  int64_t mission_covered_cells = 0;
  int64_t mission_cut_off_cells = 0;
  int64_t mission_obstructed_cells = 0;
  double map_free_area_m2 = 0.0;
  // The floor measured on the map's pixels, not on the grid
  // (planner/plan/floor_measure.h): the free area a tool disc can touch in
  // the robot's part of the map (in the regions, when given), the share of
  // it the path sweeps, and what it misses. 0: not measured (a fleet
  // robot's share, a replanned plan, a map without pixels).
  double reachable_area_m2 = 0.0;
  double swept_reachable_ratio = 0.0;
  double missed_reachable_m2 = 0.0;
  // Timing (wall clock, milliseconds).
  double planning_ms = 0.0;
  double grid_ms = 0.0;
  double partition_ms = 0.0;
  double transitions_ms = 0.0;
  double tour_ms = 0.0;
  double floor_ms = 0.0;              // the floor measure (its per-area part when not cached)
  bool tour_cut_short = false;        // kept for old callers: termination.limit_reached()
  bool decomposition_cached = false;  // every per-map artifact came from the cache
  PlanOrigin plan_source = PlanOrigin::kCold;  // set by the engine
  std::string partition_solver;
  std::string tour_solver;
  // Battery plans only (planner/energy): energy in the battery's units.
  int64_t charge_cycles = 0;
  double energy_total = 0.0;          // sum over the cycles
  double energy_unconstrained = 0.0;  // the same tour from the station and back, no charges
  double energy_lower_bound =
      0.0;  // unconstrained + the return legs no split avoids (see charge_cycles.h)
};

// One charge cycle of a battery plan: path[first_waypoint] and
// path[last_waypoint] are at the station; the robot drives to
// path[resume_waypoint], works, and must leave for the station at
// path[leave_waypoint].
struct ChargeCycle {
  int first_waypoint = 0;
  int last_waypoint = 0;
  int resume_waypoint = 0;
  int leave_waypoint = 0;
  double energy = 0.0;            // the whole cycle, station to station
  double energy_at_leave = 0.0;   // used when leaving for the station
  int resume_unit = -1;           // tag (Waypoint::rank) of the unit work resumes in
  bool resumes_mid_unit = false;  // the previous cycle left this unit unfinished
};

// Planner-specific detail, beside the planner-neutral result.
class PlannerDetail {
 public:
  virtual ~PlannerDetail() = default;
  virtual size_t MemoryBytes() const = 0;
};

struct CoveragePlan {
  std::string planner;               // registered name, e.g. "oarp"
  std::shared_ptr<const Grid> grid;  // the grid the path was planned on (drive grid)
  std::vector<Waypoint> path;
  std::vector<CoverageSweep> sweeps;  // one per coverage segment, in path order
  std::vector<ChargeCycle> cycles;    // battery plans only, in path order
  PlanStats stats;
  Termination termination;
  std::shared_ptr<const PlannerDetail> detail;
  // The planner's TourModel vertices in visiting order (planners that
  // SupportsWarmStart only; empty otherwise): what a later request with
  // another start pose warm-starts from.
  std::vector<int> tour_vertices;

  template <typename T>
  const T* detail_as() const {
    return dynamic_cast<const T*>(detail.get());
  }
  size_t MemoryBytes() const;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_COVERAGE_PLAN_H_
