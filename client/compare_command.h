// `covplan compare`: plans one map with each named planner through the
// engine, in this process, and prints one table (and optionally JSON) so a
// robot team can choose a planner on its own map.
//
//   covplan compare --map site.yaml --algorithms oarp,stc --tool-width 0.8 --json cmp.json
//
// Columns, all from the plan itself: turns, path length, estimated duration
// (the robot model's drive + turn time), covered free-area ratio (the share
// of the map's free area inside the cells swept), redundant cells (cells to
// cover that the path's centre line enters more than once, transitions
// included) and planning time (wall clock of the engine call, each planner
// with a fresh artifact cache, so every planner pays for the grid).
// With --robots K each planner plans a K-robot fleet instead (both
// divisions): makespan, its lower bound, the gap and the equal-area makespan.
// Thread-safety: not applicable (command entry points).
#ifndef COVPLAN_CLIENT_COMPARE_COMMAND_H_
#define COVPLAN_CLIENT_COMPARE_COMMAND_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/engine/engine.h"

namespace covplan {

struct ComparisonRow {
  std::string planner;
  int64_t turns = 0;
  double length_m = 0.0;
  double duration_s = 0.0;
  double covered_free_area_ratio = 0.0;
  int64_t cells_to_cover = 0;
  int64_t covered_cells = 0;
  int64_t redundant_cells = 0;
  double planning_ms = 0.0;
  std::string termination;  // "converged" or the limit
};

// Cells to cover (area.cover) that the path's centre line enters more than
// once (sampled every 1 % of a cell; the start counts as the first entry).
int64_t CountRedundantCells(const CoverageArea& area, const std::vector<Waypoint>& path);

// Plans `source` with each planner of `planners` (request.planner is
// replaced, request.options reset to each planner's defaults).
// InvalidArgument naming the registered planners for an unknown name.
absl::StatusOr<std::vector<ComparisonRow>> ComparePlanners(const PlannerRegistry& registry,
                                                           const MapSource& source,
                                                           const std::vector<std::string>& planners,
                                                           const PlanRequest& request,
                                                           const EngineLimits& limits);

// The rows as a fixed-width text table, a markdown table (with a leading
// `map` column when `map_name` is not empty) and a JSON object.
std::string ComparisonTable(const std::vector<ComparisonRow>& rows);
std::string ComparisonMarkdown(const std::vector<ComparisonRow>& rows, const std::string& map_name,
                               bool header);
std::string ComparisonJson(const std::vector<ComparisonRow>& rows, const std::string& map_path,
                           double tool_width_m);

// `covplan compare --robots K`: each planner plans the map as a K-robot
// fleet (robots without start poses, spread by the planner), once with the
// makespan division and once with the equal-area baseline.
struct FleetComparisonRow {
  std::string planner;
  int robots = 0;
  double makespan_s = 0.0;     // makespan division
  double lower_bound_s = 0.0;  // the fleet's makespan lower bound
  double gap = 0.0;            // makespan / lower bound - 1
  double equal_area_makespan_s = 0.0;
  double equal_area_gap = 0.0;
  int64_t cells_to_cover = 0;
  int64_t covered_cells = 0;  // by the makespan fleet
  double planning_ms = 0.0;   // both fleets
  std::string termination;    // the makespan fleet's
};

// `request`'s robot model is every robot's; each planner gets its own
// artifact cache, shared by its two fleets.
absl::StatusOr<std::vector<FleetComparisonRow>> CompareFleets(
    const PlannerRegistry& registry, const MapSource& source,
    const std::vector<std::string>& planners, const PlanRequest& request, int robots,
    const EngineLimits& limits);

std::string FleetComparisonTable(const std::vector<FleetComparisonRow>& rows);
std::string FleetComparisonMarkdown(const std::vector<FleetComparisonRow>& rows,
                                    const std::string& map_name, bool header);
std::string FleetComparisonJson(const std::vector<FleetComparisonRow>& rows,
                                const std::string& map_path, double tool_width_m);

// Returns the process exit code.
int RunCompareCommand(const std::vector<std::string>& args);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_COMPARE_COMMAND_H_
