#include "client/geo_site.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

absl::Status ProjectPose(const GeoFrame& frame, const std::string& what, v1::Pose* pose) {
  ASSIGN_OR_RETURN(Point2 p, frame.Forward({pose->x(), pose->y()}, what));
  pose->set_x(p.x);
  pose->set_y(p.y);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::optional<GeoFrame>> ProjectIntoSite(const std::optional<std::string>& crs,
                                                        v1::Map* map, v1::PlanRequest* request,
                                                        std::vector<FleetRobot>* fleet) {
  if (!crs) return std::optional<GeoFrame>();
  if (!map->has_polygons()) {
    return absl::InvalidArgumentError(
        "--crs needs a GeoJSON polygon map: an image map is in its own metric frame");
  }
  ASSIGN_OR_RETURN(GeoFrame frame,
                   GeoFrame::ForSite(*crs, map->polygons().polygons(), "map.polygons"));
  RETURN_IF_ERROR(frame.Project(map->mutable_polygons()->mutable_polygons(), "map.polygons"));
  RETURN_IF_ERROR(frame.Project(request->mutable_regions(), "--region"));
  RETURN_IF_ERROR(frame.Project(request->mutable_no_go(), "--no-go"));
  v1::RobotModel* robot = request->mutable_robot();
  if (robot->has_start()) RETURN_IF_ERROR(ProjectPose(frame, "--start", robot->mutable_start()));
  if (robot->has_end()) RETURN_IF_ERROR(ProjectPose(frame, "--end", robot->mutable_end()));
  if (request->has_battery() && request->battery().has_station()) {
    RETURN_IF_ERROR(ProjectPose(frame, "--station", request->mutable_battery()->mutable_station()));
  }
  if (fleet != nullptr) {
    for (FleetRobot& r : *fleet) {
      if (!r.robot.start) continue;
      ASSIGN_OR_RETURN(Point2 p, frame.Forward({r.robot.start->x, r.robot.start->y},
                                               absl::StrCat("--robot ", r.id)));
      r.robot.start->x = p.x;
      r.robot.start->y = p.y;
    }
  }
  return std::optional<GeoFrame>(std::move(frame));
}

ExportFrame ExportFrameOf(const std::optional<GeoFrame>& frame) {
  ExportFrame out;
  if (!frame) return out;
  out.crs = frame->crs();
  out.geographic = frame->geographic();
  out.to_crs = [f = *frame](double x, double y) {
    const Point2 p = f.Inverse({x, y});
    return std::pair{p.x, p.y};
  };
  return out;
}

}  // namespace covplan
