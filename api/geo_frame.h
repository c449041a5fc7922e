// A site given in geographic or projected coordinates, planned in a local
// metric frame. Coordinates in a CRS that PROJ knows (by default EPSG:4326,
// longitude/latitude as RFC 7946 GeoJSON has them; or e.g. a UTM zone,
// "EPSG:32632") go through the CRS's own geographic coordinates onto a
// transverse Mercator on its ellipsoid, centred on the site (k = 1, x east
// and y north in metres) and shifted so the corner of the site's extent is
// (0, 0) (the grid then meets the site's edges as it meets a site drawn in
// metres from its corner), where covplan grids and plans; Inverse brings plan
// coordinates back. Positions are in GeoJSON's order (x = longitude or
// easting, y = latitude or northing), whatever the CRS's official axis order.
//
//   ASSIGN_OR_RETURN(GeoFrame frame, GeoFrame::ForSite("EPSG:4326", map.polygons()));
//   RETURN_IF_ERROR(frame.Project(map.mutable_polygons(), "map.polygons"));
//   Point2 lon_lat = frame.Inverse({x, y});
//
// Errors are InvalidArgument naming the CRS or the vertex ("map.polygons[0].outer.points[3]:
// latitude 91 is outside [-90, 90]").
// Thread-safety: a GeoFrame is not safe for concurrent use (PROJ objects are
// per thread); copies share it.
#ifndef COVPLAN_API_GEO_FRAME_H_
#define COVPLAN_API_GEO_FRAME_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

class GeoFrame {
 public:
  // The frame of a site whose polygons are in `crs`: its central meridian and
  // latitude the middle of their extent in the CRS's geographic coordinates,
  // its origin the lower-left corner of their projected extent.
  static absl::StatusOr<GeoFrame> ForSite(
      absl::string_view crs, const google::protobuf::RepeatedPtrField<v1::Polygon>& site,
      absl::string_view what = "map.polygons");

  // Every point of `polygons` from the CRS into the local frame, in place,
  // rounded to the millimetre (edges shared in the CRS stay shared).
  absl::Status Project(google::protobuf::RepeatedPtrField<v1::Polygon>* polygons,
                       absl::string_view what) const;
  // One point (or pose position) from the CRS into the local frame.
  absl::StatusOr<Point2> Forward(Point2 p, absl::string_view what) const;
  // A local point back into the CRS.
  Point2 Inverse(Point2 local) const;

  const std::string& crs() const { return crs_; }
  // Whether the CRS's positions are longitude, latitude (else easting, northing).
  bool geographic() const;
  double lon0() const { return lon0_; }
  double lat0() const { return lat0_; }
  // The local frame as a PROJ string (tmerc on the CRS's ellipsoid).
  const std::string& local_definition() const { return local_definition_; }

 private:
  struct Proj;
  GeoFrame() = default;
  // A point of the CRS in its geographic coordinates (longitude, latitude).
  absl::StatusOr<Point2> Geographic(Point2 p, absl::string_view what) const;
  std::shared_ptr<Proj> proj_;
  std::string crs_;
  std::string local_definition_;
  double lon0_ = 0.0, lat0_ = 0.0;
};

}  // namespace covplan

#endif  // COVPLAN_API_GEO_FRAME_H_
