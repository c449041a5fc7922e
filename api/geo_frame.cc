#include "api/geo_frame.h"

#include <proj.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {

struct GeoFrame::Proj {
  PJ_CONTEXT* ctx = nullptr;
  PJ* to_geographic = nullptr;  // the CRS -> its own geographic CRS (lon, lat degrees)
  PJ* local = nullptr;          // lon, lat degrees -> the local tmerc (metres)
  bool geographic_input = false;
  ~Proj() {
    if (local != nullptr) proj_destroy(local);
    if (to_geographic != nullptr) proj_destroy(to_geographic);
    if (ctx != nullptr) proj_context_destroy(ctx);
  }
};

namespace {

std::string ProjError(PJ_CONTEXT* ctx) {
  const char* text = proj_context_errno_string(ctx, proj_context_errno(ctx));
  return text != nullptr ? text : "unknown PROJ error";
}

// A PJ that is destroyed with its scope (for the intermediate objects).
struct Owned {
  PJ* pj;
  ~Owned() {
    if (pj != nullptr) proj_destroy(pj);
  }
};

bool Finite(PJ_COORD c) { return std::isfinite(c.xy.x) && std::isfinite(c.xy.y); }

std::string PointName(absl::string_view what, int polygon, int ring, int point) {
  return ring < 0 ? absl::StrCat(what, "[", polygon, "].outer.points[", point, "]")
                  : absl::StrCat(what, "[", polygon, "].holes[", ring, "].points[", point, "]");
}

// Calls `f(point, name)` on every point of `polygons`; stops at the first error.
template <typename F>
absl::Status ForEachPoint(const google::protobuf::RepeatedPtrField<v1::Polygon>& polygons,
                          absl::string_view what, F f) {
  for (int i = 0; i < polygons.size(); ++i) {
    for (int j = 0; j < polygons[i].outer().points_size(); ++j)
      RETURN_IF_ERROR(f(polygons[i].outer().points(j), PointName(what, i, -1, j)));
    for (int h = 0; h < polygons[i].holes_size(); ++h) {
      for (int j = 0; j < polygons[i].holes(h).points_size(); ++j)
        RETURN_IF_ERROR(f(polygons[i].holes(h).points(j), PointName(what, i, h, j)));
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<GeoFrame> GeoFrame::ForSite(
    absl::string_view crs, const google::protobuf::RepeatedPtrField<v1::Polygon>& site,
    absl::string_view what) {
  GeoFrame frame;
  frame.crs_ = std::string(crs);
  frame.proj_ = std::make_shared<Proj>();
  Proj& p = *frame.proj_;
  p.ctx = proj_context_create();
  proj_log_level(p.ctx, PJ_LOG_NONE);
  Owned source{proj_create(p.ctx, frame.crs_.c_str())};
  if (source.pj == nullptr || !proj_is_crs(source.pj)) {
    return absl::InvalidArgumentError(
        absl::StrCat("crs '", crs, "': not a coordinate reference system PROJ knows (",
                     ProjError(p.ctx), "); e.g. EPSG:4326 or a UTM zone such as EPSG:32632"));
  }
  const PJ_TYPE type = proj_get_type(source.pj);
  p.geographic_input = type == PJ_TYPE_GEOGRAPHIC_2D_CRS || type == PJ_TYPE_GEOGRAPHIC_3D_CRS;
  if (!p.geographic_input && type != PJ_TYPE_PROJECTED_CRS) {
    return absl::InvalidArgumentError(absl::StrCat(
        "crs '", crs, "' is neither a geographic nor a projected CRS: covplan reads 2D positions"));
  }
  Owned geodetic{proj_crs_get_geodetic_crs(p.ctx, source.pj)};
  Owned ellipsoid{proj_get_ellipsoid(p.ctx, source.pj)};
  double a = 0.0, b = 0.0, inverse_flattening = 0.0;
  int computed = 0;
  Owned op{geodetic.pj == nullptr
               ? nullptr
               : proj_create_crs_to_crs_from_pj(p.ctx, source.pj, geodetic.pj, nullptr, nullptr)};
  if (op.pj == nullptr || ellipsoid.pj == nullptr ||
      !proj_ellipsoid_get_parameters(p.ctx, ellipsoid.pj, &a, &b, &computed, &inverse_flattening)) {
    return absl::InvalidArgumentError(
        absl::StrCat("crs '", crs, "': PROJ cannot relate it to its geographic coordinates (",
                     ProjError(p.ctx), ")"));
  }
  p.to_geographic = proj_normalize_for_visualization(p.ctx, op.pj);
  if (p.to_geographic == nullptr) return absl::InternalError("PROJ: " + ProjError(p.ctx));

  double lon_lo = 1e9, lon_hi = -1e9, lat_lo = 1e9, lat_hi = -1e9;
  RETURN_IF_ERROR(ForEachPoint(site, what, [&](const v1::Point2& q, const std::string& name) {
    ASSIGN_OR_RETURN(Point2 g, frame.Geographic({q.x(), q.y()}, name));
    lon_lo = std::min(lon_lo, g.x);
    lon_hi = std::max(lon_hi, g.x);
    lat_lo = std::min(lat_lo, g.y);
    lat_hi = std::max(lat_hi, g.y);
    return absl::OkStatus();
  }));
  if (lon_lo > lon_hi) return absl::InvalidArgumentError(absl::StrCat(what, ": no points"));
  if (lon_hi - lon_lo > 180.0) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " spans ", lon_hi - lon_lo,
                     " degrees of longitude: a site must not cross the antimeridian"));
  }
  frame.lon0_ = 0.5 * (lon_lo + lon_hi);
  frame.lat0_ = 0.5 * (lat_lo + lat_hi);
  // First centred on the site, then shifted so that the corner of the site's
  // extent is the frame's (0, 0), as a site drawn in metres from its corner
  // is: the grid's cells then line up with the site's edges the same way.
  auto make_local = [&](double x0, double y0) -> absl::Status {
    if (p.local != nullptr) proj_destroy(p.local);
    frame.local_definition_ = absl::StrFormat(
        "+proj=tmerc +lat_0=%.12f +lon_0=%.12f +k=1 +x_0=%.9f +y_0=%.9f +a=%.6f +b=%.6f +units=m",
        frame.lat0_, frame.lon0_, x0, y0, a, b);
    p.local = proj_create(p.ctx, absl::StrCat("+proj=pipeline +step +proj=unitconvert "
                                              "+xy_in=deg +xy_out=rad +step ",
                                              frame.local_definition_)
                                     .c_str());
    if (p.local == nullptr) return absl::InternalError("PROJ tmerc: " + ProjError(p.ctx));
    return absl::OkStatus();
  };
  RETURN_IF_ERROR(make_local(0.0, 0.0));
  double x_lo = std::numeric_limits<double>::infinity(), y_lo = x_lo;
  RETURN_IF_ERROR(ForEachPoint(site, what, [&](const v1::Point2& q, const std::string& name) {
    ASSIGN_OR_RETURN(Point2 local, frame.Forward({q.x(), q.y()}, name));
    x_lo = std::min(x_lo, local.x);
    y_lo = std::min(y_lo, local.y);
    return absl::OkStatus();
  }));
  RETURN_IF_ERROR(make_local(-x_lo, -y_lo));
  return frame;
}

absl::StatusOr<Point2> GeoFrame::Geographic(Point2 q, absl::string_view name) const {
  if (!std::isfinite(q.x) || !std::isfinite(q.y))
    return absl::InvalidArgumentError(absl::StrCat(name, ": not a finite position"));
  if (proj_->geographic_input) {
    if (q.x < -180.0 || q.x > 180.0) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": longitude ", q.x, " is outside [-180, 180]"));
    }
    if (q.y < -90.0 || q.y > 90.0) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": latitude ", q.y,
                                                     " is outside [-90, 90] (GeoJSON positions are "
                                                     "[longitude, latitude])"));
    }
  }
  const PJ_COORD g = proj_trans(proj_->to_geographic, PJ_FWD, proj_coord(q.x, q.y, 0, 0));
  if (!Finite(g)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": (", q.x, ", ", q.y, ") cannot be placed in ", crs_));
  }
  return Point2{g.xy.x, g.xy.y};
}

bool GeoFrame::geographic() const { return proj_->geographic_input; }

absl::StatusOr<Point2> GeoFrame::Forward(Point2 q, absl::string_view name) const {
  ASSIGN_OR_RETURN(Point2 g, Geographic(q, name));
  const PJ_COORD local = proj_trans(proj_->local, PJ_FWD, proj_coord(g.x, g.y, 0, 0));
  if (!Finite(local)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": (", q.x, ", ", q.y, ") cannot be placed in the site's frame"));
  }
  return Point2{local.xy.x, local.xy.y};
}

Point2 GeoFrame::Inverse(Point2 local) const {
  const PJ_COORD g = proj_trans(proj_->local, PJ_INV, proj_coord(local.x, local.y, 0, 0));
  const PJ_COORD c = proj_trans(proj_->to_geographic, PJ_INV, g);
  return Point2{c.xy.x, c.xy.y};
}

absl::Status GeoFrame::Project(google::protobuf::RepeatedPtrField<v1::Polygon>* polygons,
                               absl::string_view what) const {
  for (int i = 0; i < polygons->size(); ++i) {
    v1::Polygon& polygon = (*polygons)[i];
    for (int h = -1; h < polygon.holes_size(); ++h) {
      v1::Ring* ring = h < 0 ? polygon.mutable_outer() : polygon.mutable_holes(h);
      for (int j = 0; j < ring->points_size(); ++j) {
        v1::Point2* q = ring->mutable_points(j);
        ASSIGN_OR_RETURN(Point2 local, Forward({q->x(), q->y()}, PointName(what, i, h, j)));
        // To the millimetre: a parallel of latitude is slightly curved in the frame (4 um
        // over 14 m at 48 deg), so two polygons sharing an edge in the CRS would leave a
        // sliver between them that blocks the robot; rounded, they share it again.
        q->set_x(std::round(local.x * 1000.0) / 1000.0);
        q->set_y(std::round(local.y * 1000.0) / 1000.0);
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace covplan
