#include "api/plan_export.h"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace covplan {
namespace {

using google::protobuf::ListValue;
using google::protobuf::Struct;
using google::protobuf::Value;

Value Number(double v) {
  Value out;
  out.set_number_value(v);
  return out;
}

Value Text(std::string v) {
  Value out;
  out.set_string_value(std::move(v));
  return out;
}

Value List(std::vector<Value> items) {
  Value out;
  for (Value& item : items) *out.mutable_list_value()->add_values() = std::move(item);
  return out;
}

// A position [x, y] of the map frame, in the export's CRS.
Value Position(const ExportFrame& f, double x, double y) {
  if (f.to_crs) std::tie(x, y) = f.to_crs(x, y);
  return List({Number(x), Number(y)});
}

Value Object(std::vector<std::pair<std::string, Value>> fields) {
  Value out;
  for (auto& [key, value] : fields) (*out.mutable_struct_value()->mutable_fields())[key] = value;
  return out;
}

Value Geometry(const char* type, Value coordinates) {
  return Object({{"type", Text(type)}, {"coordinates", std::move(coordinates)}});
}

Value Feature(const char* name, Value geometry, std::vector<std::pair<std::string, Value>> props) {
  props.emplace_back("feature", Text(name));
  return Object({{"type", Text("Feature")},
                 {"geometry", std::move(geometry)},
                 {"properties", Object(std::move(props))}});
}

// A ring closed and oriented by RFC 7946's right-hand rule: exteriors
// counter-clockwise, holes clockwise.
Value Ring(const ExportFrame& f, const v1::Ring& ring, bool exterior) {
  std::vector<std::pair<double, double>> points;
  for (const v1::Point2& p : ring.points())
    points.push_back(f.to_crs ? f.to_crs(p.x(), p.y()) : std::pair{p.x(), p.y()});
  if (!points.empty() && points.front() != points.back()) points.push_back(points.front());
  double twice_area = 0.0;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    twice_area += points[i].first * points[i + 1].second - points[i + 1].first * points[i].second;
  }
  if ((twice_area > 0.0) != exterior) std::reverse(points.begin(), points.end());
  std::vector<Value> positions;
  for (const auto& [x, y] : points) positions.push_back(Position(ExportFrame(), x, y));
  return List(std::move(positions));
}

Value PolygonGeometry(const ExportFrame& f, const v1::Polygon& polygon) {
  std::vector<Value> rings{Ring(f, polygon.outer(), true)};
  for (const v1::Ring& hole : polygon.holes()) rings.push_back(Ring(f, hole, false));
  return Geometry("Polygon", List(std::move(rings)));
}

Value PathFeature(const ExportFrame& f, const v1::PlanResponse& plan) {
  std::vector<Value> positions, times, headings, kinds, ranks;
  for (const v1::Waypoint& w : plan.path()) {
    positions.push_back(Position(f, w.x(), w.y()));
    times.push_back(Number(w.time_s()));
    headings.push_back(Number(w.theta()));
    kinds.push_back(Text(v1::SegmentKind_Name(w.kind())));
    ranks.push_back(Number(w.rank()));
  }
  return Feature("path", Geometry("LineString", List(std::move(positions))),
                 {{"plan_id", Text(plan.plan_id())},
                  {"planner", Text(plan.planner())},
                  {"duration_s", Number(plan.stats().estimated_duration_s())},
                  {"times_s", List(std::move(times))},
                  {"headings_rad", List(std::move(headings))},
                  {"kinds", List(std::move(kinds))},
                  {"ranks", List(std::move(ranks))}});
}

Value CellCentre(const ExportFrame& f, const v1::Grid& grid, const v1::CellRef& cell) {
  return Position(f, grid.origin_x_m() + (cell.col() + 0.5) * grid.cell_size_m(),
                  grid.origin_y_m() + (cell.row() + 0.5) * grid.cell_size_m());
}

void AddUnitsAndCycles(const ExportFrame& f, const v1::PlanResponse& plan,
                       std::vector<Value>* features) {
  for (int i = 0; i < plan.ranks_size(); ++i) {
    const v1::Rank& rank = plan.ranks(i);
    features->push_back(Feature(
        "rank",
        Geometry("LineString", List({CellCentre(f, plan.grid(), rank.first_cell()),
                                     CellCentre(f, plan.grid(), rank.last_cell())})),
        {{"index", Number(i)}, {"orientation", Text(v1::Orientation_Name(rank.orientation()))}}));
  }
  for (int c = 0; c < plan.cycles_size(); ++c) {
    const v1::ChargeCycle& cycle = plan.cycles(c);
    std::vector<Value> positions;
    for (int w = std::max(0, cycle.first_waypoint());
         w <= cycle.last_waypoint() && w < plan.path_size(); ++w) {
      positions.push_back(Position(f, plan.path(w).x(), plan.path(w).y()));
    }
    if (positions.size() < 2) continue;
    features->push_back(Feature("cycle", Geometry("LineString", List(std::move(positions))),
                                {{"index", Number(c)}, {"energy", Number(cycle.energy())}}));
  }
}

absl::StatusOr<std::string> Print(const google::protobuf::Message& message) {
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(message, &json);
  if (!status.ok()) return absl::InternalError(absl::StrCat("JSON: ", status.ToString()));
  return json + "\n";
}

Value Stamp(double unix_s) {
  double sec = std::floor(unix_s);
  double nanosec = std::round((unix_s - sec) * 1e9);
  if (nanosec >= 1e9) {
    sec += 1.0;
    nanosec -= 1e9;
  }
  return Object({{"sec", Number(sec)}, {"nanosec", Number(nanosec)}});
}

}  // namespace

absl::StatusOr<std::string> PlanToGeoJson(const v1::PlanResponse& plan, const ExportFrame& frame) {
  std::vector<Value> features{PathFeature(frame, plan)};
  AddUnitsAndCycles(frame, plan, &features);
  for (const v1::Polygon& zone : plan.regions())
    features.push_back(Feature("region", PolygonGeometry(frame, zone), {}));
  for (const v1::Polygon& zone : plan.no_go())
    features.push_back(Feature("no_go", PolygonGeometry(frame, zone), {}));
  std::vector<std::pair<std::string, Value>> members = {{"type", Text("FeatureCollection")},
                                                        {"features", List(std::move(features))}};
  if (!frame.crs.empty() && frame.crs != "EPSG:4326" && frame.crs != "OGC:CRS84") {
    // RFC 7946 has no CRS member; GeoJSON 2008's "named CRS" tells readers that know it.
    members.emplace_back("crs", Object({{"type", Text("name")},
                                        {"properties", Object({{"name", Text(frame.crs)}})}}));
  }
  return Print(Object(std::move(members)).struct_value());
}

std::string PlanToCsv(const v1::PlanResponse& plan, const ExportFrame& frame) {
  std::string out = frame.geographic ? "lon,lat" : "x,y";
  out += ",heading_rad,time_s,kind,rank\n";
  for (const v1::Waypoint& w : plan.path()) {
    auto [x, y] = frame.to_crs ? frame.to_crs(w.x(), w.y()) : std::pair{w.x(), w.y()};
    absl::StrAppendFormat(&out, "%.17g,%.17g,%.17g,%.17g,%s,%d\n", x, y, w.theta(), w.time_s(),
                          v1::SegmentKind_Name(w.kind()), w.rank());
  }
  return out;
}

absl::StatusOr<std::string> PlanToNavPath(const v1::PlanResponse& plan,
                                          const NavPathOptions& options) {
  if (options.frame_id.empty()) return absl::InvalidArgumentError("the frame id is empty");
  auto header = [&](double t) {
    return Object({{"frame_id", Text(options.frame_id)}, {"stamp", Stamp(t)}});
  };
  std::vector<Value> poses;
  for (const v1::Waypoint& w : plan.path()) {
    Value position = Object({{"x", Number(w.x())}, {"y", Number(w.y())}, {"z", Number(0.0)}});
    Value orientation = Object({{"x", Number(0.0)},
                                {"y", Number(0.0)},
                                {"z", Number(std::sin(w.theta() / 2.0))},
                                {"w", Number(std::cos(w.theta() / 2.0))}});
    poses.push_back(Object(
        {{"header", header(options.start_stamp_s + w.time_s())},
         {"pose", Object({{"position", std::move(position)}, {"orientation", orientation}})}}));
  }
  const Value path =
      Object({{"header", header(options.start_stamp_s)}, {"poses", List(std::move(poses))}});
  return Print(path.struct_value());
}

}  // namespace covplan
