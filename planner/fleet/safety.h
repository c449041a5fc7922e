// The fleet's safety report: every robot starts at time 0 and follows its
// timed plan (turns in place, then each straight segment on its trapezoidal
// speed profile; a battery robot waits recharge_s at the station between
// cycles; a robot that has finished stays at its last waypoint). The report
// samples every pair's distance and gives the closest approach and each
// interval during which a pair is closer than the clearance. A robot with
// no path (idle, without a start) stands nowhere and is not in the report.
// Avoidance is not planned: this says where the timed plans would meet.
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_FLEET_SAFETY_H_
#define COVPLAN_PLANNER_FLEET_SAFETY_H_

#include <string>
#include <vector>

#include "planner/fleet/fleet_request.h"

namespace covplan {

// A plan's waypoints with the time the robot reaches each.
class TimedPath {
 public:
  TimedPath(const std::vector<Waypoint>& path, const RobotModel& robot,
            const std::vector<ChargeCycle>& cycles = {}, double recharge_s = 0.0);
  Point2 At(double t) const;
  double end_time() const { return times_.empty() ? 0.0 : times_.back(); }

 private:
  std::vector<Waypoint> path_;
  std::vector<double> depart_;  // when the robot leaves waypoint i-1 along segment i
  std::vector<double> times_;   // when it reaches waypoint i
  RobotModel robot_;
};

FleetSafety FleetSafetyReport(const std::vector<std::string>& ids,
                              const std::vector<TimedPath>& paths, double clearance_m);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_SAFETY_H_
