// A plan in the formats robot stacks read, written from its PlanResponse (what
// the server answers, plan.json holds and GetPlan returns):
//
//   ASSIGN_OR_RETURN(std::string geojson, PlanToGeoJson(response));  // or (response, frame)
//   ASSIGN_OR_RETURN(std::string csv, PlanToCsv(response));
//   ASSIGN_OR_RETURN(std::string path, PlanToNavPath(response, {.frame_id = "map"}));
//
// - GeoJSON: a FeatureCollection (RFC 7946 structure: closed rings, exteriors
//   counter-clockwise and holes clockwise, positions [x, y]) in the map
//   frame, metres. Features, each with a "feature" property naming it: the
//   path ("path": a LineString with per-vertex "times_s", "headings_rad",
//   "kinds" and "ranks" arrays), each rank of an OARP plan ("rank": the line
//   between its end cells' centres), each charge cycle ("cycle": its part of
//   the path, with its energy), the regions and no-go zones ("region",
//   "no_go": Polygons).
// - CSV: a header, then one line per waypoint: x,y,heading_rad,time_s,kind,rank
//   (numbers printed to round-trip exactly).
// Each is InvalidArgument for a plan without a path, or whose waypoints carry
// no times (a plan.json from before they did). A path of one waypoint (an
// idle fleet robot) is a GeoJSON Point.
// - nav_msgs/Path as JSON (the ROS 2 message's fields, as rosbridge and
//   rclpy's message converters take them): header (frame_id, stamp) and one
//   PoseStamped per waypoint, its stamp the start stamp plus the waypoint's
//   time_s (all 0 without a start stamp), its orientation the quaternion of a
//   yaw of theta.
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_API_PLAN_EXPORT_H_
#define COVPLAN_API_PLAN_EXPORT_H_

#include <functional>
#include <string>
#include <utility>

#include "absl/status/statusor.h"
#include "covplan/v1/covplan.pb.h"

namespace covplan {

// Where exported positions go: by default the map frame as planned; for a
// site given in a CRS (api/geo_frame.h), back into it. Headings stay the
// plan's (radians, counter-clockwise from the frame's x axis).
struct ExportFrame {
  std::string crs;          // "" = the map frame; else written into the GeoJSON (unless EPSG:4326)
  bool geographic = false;  // positions are longitude, latitude (CSV columns lon,lat)
  std::function<std::pair<double, double>(double, double)> to_crs;  // unset: identity
};

absl::StatusOr<std::string> PlanToGeoJson(const v1::PlanResponse& plan,
                                          const ExportFrame& frame = {});

absl::StatusOr<std::string> PlanToCsv(const v1::PlanResponse& plan, const ExportFrame& frame = {});

struct NavPathOptions {
  std::string frame_id = "map";
  // Unix seconds of the path's start: each pose is stamped start + its time_s.
  // 0: every stamp 0 ("unset", which ROS reads as "the latest").
  double start_stamp_s = 0.0;
};
absl::StatusOr<std::string> PlanToNavPath(const v1::PlanResponse& plan,
                                          const NavPathOptions& options);

}  // namespace covplan

#endif  // COVPLAN_API_PLAN_EXPORT_H_
