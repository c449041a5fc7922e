// The result every coverage planner produces: waypoints with headings, the
// ranks (for rank-based planners) and statistics.
//
// Thread-safety: plain value types.
#ifndef COVPLAN_PLANNER_PLAN_COVERAGE_PLAN_H_
#define COVPLAN_PLANNER_PLAN_COVERAGE_PLAN_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "planner/grid/grid.h"
#include "planner/partition/rank.h"

namespace covplan {

enum class SegmentKind : uint8_t {
  kStart = 0,       // first waypoint; no segment ends here
  kCoverage = 1,    // the straight segment ending here covers a rank
  kTransition = 2,  // the segment ending here moves between ranks (tool not sweeping new cells)
};

struct Waypoint {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;  // heading while driving the segment that ends here (rad)
  SegmentKind kind = SegmentKind::kStart;
  int rank = -1;       // rank index for coverage segments, else -1
};

struct PlanStats {
  int64_t num_ranks = 0;
  int64_t num_turns = 0;            // heading changes > 1e-6 rad along the path
  double coverage_length_m = 0.0;
  double transition_length_m = 0.0;
  double covered_free_area_ratio = 0.0;
  double estimated_duration_s = 0.0;  // coverage + transition driving + turning
  double turning_time_s = 0.0;
  int64_t grid_rows = 0;
  int64_t grid_cols = 0;
  int64_t free_cells = 0;
  int64_t unreachable_free_cells = 0;  // free cells not connected to the planned area
  double map_free_area_m2 = 0.0;
  // Timing (wall clock, milliseconds).
  double planning_ms = 0.0;
  double grid_ms = 0.0;
  double partition_ms = 0.0;
  double transitions_ms = 0.0;
  double tour_ms = 0.0;
  bool tour_cut_short = false;   // the deadline stopped the tour search
  bool decomposition_cached = false;
  std::string partition_solver;
  std::string tour_solver;
};

struct CoveragePlan {
  std::shared_ptr<const Grid> grid;
  std::vector<Rank> ranks;        // all ranks of the partition
  std::vector<int> rank_order;    // visiting order (indices into ranks)
  std::vector<bool> rank_reversed;  // per visit in rank_order: traversed last->first
  std::vector<Waypoint> path;
  PlanStats stats;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PLAN_COVERAGE_PLAN_H_
