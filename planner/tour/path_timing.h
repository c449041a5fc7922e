// Drive time of a polyline under the robot model: every straight segment is a
// rest-to-rest trapezoidal profile; every heading change is an in-place turn.
// The single place where plan durations are computed, so tour costs and
// reported plan statistics agree by construction.
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_TOUR_PATH_TIMING_H_
#define COVPLAN_PLANNER_TOUR_PATH_TIMING_H_

#include <optional>
#include <vector>

#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

inline constexpr double kTurnEpsilonRad = 1e-6;
inline constexpr double kMinSegmentM = 1e-9;

struct PolylineTiming {
  double time_s = 0.0;
  double length_m = 0.0;
  double turn_time_s = 0.0;
  int turns = 0;
  double final_heading = 0.0;  // heading after the last segment (or heading_in)
};

// Times driving through `points` in order. `heading_in` is the robot's
// heading at points[0] (no initial turn if absent); `heading_out`, if given,
// adds the final turn onto it. Zero-length segments are skipped.
PolylineTiming TimePolyline(const RobotModel& robot, const std::vector<Point2>& points,
                            std::optional<double> heading_in, std::optional<double> heading_out);

// When the robot reaches each waypoint of `path`, from 0 at path[0]: at each
// waypoint it turns in place onto the next segment's heading, then drives it
// rest to rest (as PlanStats.estimated_duration_s counts, whose value is the
// last entry). With `cycles` (a battery plan) it also waits `recharge_s` at
// the station after every cycle but the last.
std::vector<double> ArrivalTimes(const RobotModel& robot, const std::vector<Waypoint>& path,
                                 const std::vector<ChargeCycle>& cycles = {},
                                 double recharge_s = 0.0);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_PATH_TIMING_H_
