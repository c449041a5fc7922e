#include "api/plan_export.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "planner/common/json_text.h"

namespace covplan {
namespace {

// The JSON is written as text in a fixed key order (readable, diffable,
// reproducible), numbers by JsonNumber (they read back exactly).

std::pair<double, double> ToCrs(const ExportFrame& f, double x, double y) {
  return f.to_crs ? f.to_crs(x, y) : std::pair{x, y};
}

std::string Position(const ExportFrame& f, double x, double y) {
  const auto [cx, cy] = ToCrs(f, x, y);
  return absl::StrCat("[", JsonNumber(cx), ", ", JsonNumber(cy), "]");
}

template <typename T, typename F>
std::string Array(const T& items, F f) {
  std::vector<std::string> parts;
  for (const auto& item : items) parts.push_back(f(item));
  return absl::StrCat("[", absl::StrJoin(parts, ", "), "]");
}

std::string Feature(const std::string& name, const std::string& geometry,
                    const std::string& properties = "") {
  return absl::StrCat(
      "    {\"type\": \"Feature\", \"properties\": {\"feature\": ", JsonString(name),
      properties.empty() ? "" : ", ", properties, "},\n     \"geometry\": ", geometry, "}");
}

std::string Geometry(const char* type, const std::string& coordinates) {
  return absl::StrCat("{\"type\": \"", type, "\", \"coordinates\": ", coordinates, "}");
}

// A ring closed and oriented by RFC 7946's right-hand rule (exteriors
// counter-clockwise, holes clockwise), in the export's CRS.
std::string Ring(const ExportFrame& f, const v1::Ring& ring, bool exterior) {
  std::vector<std::pair<double, double>> points;
  for (const v1::Point2& p : ring.points()) points.push_back(ToCrs(f, p.x(), p.y()));
  if (!points.empty() && points.front() != points.back()) points.push_back(points.front());
  double twice_area = 0.0;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    twice_area += points[i].first * points[i + 1].second - points[i + 1].first * points[i].second;
  }
  if ((twice_area > 0.0) != exterior) std::reverse(points.begin(), points.end());
  return Array(points, [](const std::pair<double, double>& p) {
    return absl::StrCat("[", JsonNumber(p.first), ", ", JsonNumber(p.second), "]");
  });
}

std::string PolygonGeometry(const ExportFrame& f, const v1::Polygon& polygon) {
  std::vector<std::string> rings{Ring(f, polygon.outer(), true)};
  for (const v1::Ring& hole : polygon.holes()) rings.push_back(Ring(f, hole, false));
  return Geometry("Polygon", absl::StrCat("[", absl::StrJoin(rings, ", "), "]"));
}

// The path: a LineString (a Point for a robot that stays where it is).
std::string PathFeature(const ExportFrame& f, const v1::PlanResponse& plan) {
  const auto& path = plan.path();
  const std::string geometry =
      path.size() == 1
          ? Geometry("Point", Position(f, path[0].x(), path[0].y()))
          : Geometry("LineString",
                     Array(path, [&](const v1::Waypoint& w) { return Position(f, w.x(), w.y()); }));
  const std::string properties = absl::StrCat(
      "\"plan_id\": ", JsonString(plan.plan_id()), ", \"planner\": ", JsonString(plan.planner()),
      ", \"duration_s\": ", JsonNumber(plan.stats().estimated_duration_s()),
      ",\n     \"times_s\": ",
      Array(path, [](const v1::Waypoint& w) { return JsonNumber(w.time_s()); }),
      ",\n     \"headings_rad\": ",
      Array(path, [](const v1::Waypoint& w) { return JsonNumber(w.theta()); }),
      ",\n     \"kinds\": ",
      Array(path, [](const v1::Waypoint& w) { return JsonString(v1::SegmentKind_Name(w.kind())); }),
      ",\n     \"ranks\": ",
      Array(path, [](const v1::Waypoint& w) { return absl::StrCat(w.rank()); }));
  return Feature("path", geometry, properties);
}

std::string CellCentre(const ExportFrame& f, const v1::Grid& grid, const v1::CellRef& cell) {
  return Position(f, grid.origin_x_m() + (cell.col() + 0.5) * grid.cell_size_m(),
                  grid.origin_y_m() + (cell.row() + 0.5) * grid.cell_size_m());
}

void AddUnitsAndCycles(const ExportFrame& f, const v1::PlanResponse& plan,
                       std::vector<std::string>* features) {
  for (int i = 0; i < plan.ranks_size(); ++i) {
    const v1::Rank& rank = plan.ranks(i);
    features->push_back(Feature(
        "rank",
        Geometry("LineString",
                 absl::StrCat("[", CellCentre(f, plan.grid(), rank.first_cell()), ", ",
                              CellCentre(f, plan.grid(), rank.last_cell()), "]")),
        absl::StrCat("\"index\": ", i,
                     ", \"orientation\": ", JsonString(v1::Orientation_Name(rank.orientation())))));
  }
  for (int c = 0; c < plan.cycles_size(); ++c) {
    const v1::ChargeCycle& cycle = plan.cycles(c);
    std::vector<std::string> positions;
    for (int w = std::max(0, cycle.first_waypoint());
         w <= cycle.last_waypoint() && w < plan.path_size(); ++w) {
      positions.push_back(Position(f, plan.path(w).x(), plan.path(w).y()));
    }
    if (positions.size() < 2) continue;
    features->push_back(Feature(
        "cycle", Geometry("LineString", absl::StrCat("[", absl::StrJoin(positions, ", "), "]")),
        absl::StrCat("\"index\": ", c, ", \"energy\": ", JsonNumber(cycle.energy()))));
  }
}

// A plan from before waypoints carried their times (or with no path) cannot
// be exported with times: say so rather than write zeros.
absl::Status CheckPath(const v1::PlanResponse& plan) {
  if (plan.path_size() == 0) return absl::InvalidArgumentError("the plan has no path");
  if (plan.path_size() > 1 && plan.path(plan.path_size() - 1).time_s() <= 0.0 &&
      plan.stats().estimated_duration_s() > 0.0) {
    return absl::InvalidArgumentError(
        "the plan's waypoints carry no times (time_s): it was written before they did; fetch "
        "it again with GetPlan or plan again");
  }
  return absl::OkStatus();
}

// Unix seconds as a ROS stamp: `start` split once, each offset added in whole
// seconds and nanoseconds with the carry (no precision lost to adding large doubles).
std::string Stamp(double start_s, double offset_s) {
  if (start_s == 0.0) return "{\"sec\": 0, \"nanosec\": 0}";
  const double start_sec = std::floor(start_s);
  const double offset_sec = std::floor(offset_s);
  int64_t sec = static_cast<int64_t>(start_sec) + static_cast<int64_t>(offset_sec);
  int64_t nanosec =
      std::llround((start_s - start_sec) * 1e9) + std::llround((offset_s - offset_sec) * 1e9);
  sec += nanosec / 1000000000;
  nanosec %= 1000000000;
  return absl::StrCat("{\"sec\": ", sec, ", \"nanosec\": ", nanosec, "}");
}

}  // namespace

absl::StatusOr<std::string> PlanToGeoJson(const v1::PlanResponse& plan, const ExportFrame& frame) {
  if (absl::Status s = CheckPath(plan); !s.ok()) return s;
  std::vector<std::string> features{PathFeature(frame, plan)};
  AddUnitsAndCycles(frame, plan, &features);
  for (const v1::Polygon& zone : plan.regions())
    features.push_back(Feature("region", PolygonGeometry(frame, zone)));
  for (const v1::Polygon& zone : plan.no_go())
    features.push_back(Feature("no_go", PolygonGeometry(frame, zone)));
  std::string crs;
  if (!frame.crs.empty() && frame.crs != "EPSG:4326" && frame.crs != "OGC:CRS84") {
    // RFC 7946 has no CRS member; GeoJSON 2008's "named CRS" tells readers that know it.
    crs = absl::StrCat(",\n  \"crs\": {\"type\": \"name\", \"properties\": {\"name\": ",
                       JsonString(frame.crs), "}}");
  }
  return absl::StrCat("{\"type\": \"FeatureCollection\"", crs, ",\n  \"features\": [\n",
                      absl::StrJoin(features, ",\n"), "\n  ]\n}\n");
}

absl::StatusOr<std::string> PlanToCsv(const v1::PlanResponse& plan, const ExportFrame& frame) {
  if (absl::Status s = CheckPath(plan); !s.ok()) return s;
  std::string out = frame.geographic ? "lon,lat" : "x,y";
  out += ",heading_rad,time_s,kind,rank\n";
  for (const v1::Waypoint& w : plan.path()) {
    const auto [x, y] = ToCrs(frame, w.x(), w.y());
    absl::StrAppend(&out, JsonNumber(x), ",", JsonNumber(y), ",", JsonNumber(w.theta()), ",",
                    JsonNumber(w.time_s()), ",", v1::SegmentKind_Name(w.kind()), ",", w.rank(),
                    "\n");
  }
  return out;
}

absl::StatusOr<std::string> PlanToNavPath(const v1::PlanResponse& plan,
                                          const NavPathOptions& options) {
  if (options.frame_id.empty()) return absl::InvalidArgumentError("the frame id is empty");
  if (!std::isfinite(options.start_stamp_s) || options.start_stamp_s < 0.0)
    return absl::InvalidArgumentError("the start stamp must be Unix seconds >= 0");
  if (absl::Status s = CheckPath(plan); !s.ok()) return s;
  const std::string frame = JsonString(options.frame_id);
  std::vector<std::string> poses;
  for (const v1::Waypoint& w : plan.path()) {
    poses.push_back(absl::StrCat("    {\"header\": {\"frame_id\": ", frame,
                                 ", \"stamp\": ", Stamp(options.start_stamp_s, w.time_s()),
                                 "},\n     \"pose\": {\"position\": {\"x\": ", JsonNumber(w.x()),
                                 ", \"y\": ", JsonNumber(w.y()),
                                 ", \"z\": 0}, \"orientation\": {\"x\": 0, \"y\": 0, \"z\": ",
                                 JsonNumber(std::sin(w.theta() / 2.0)),
                                 ", \"w\": ", JsonNumber(std::cos(w.theta() / 2.0)), "}}}"));
  }
  return absl::StrCat("{\"header\": {\"frame_id\": ", frame,
                      ", \"stamp\": ", Stamp(options.start_stamp_s, 0.0), "},\n  \"poses\": [\n",
                      absl::StrJoin(poses, ",\n"), "\n  ]\n}\n");
}

}  // namespace covplan
