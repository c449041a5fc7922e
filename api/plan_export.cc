#include "api/plan_export.h"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <string>
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

Value Position(double x, double y) { return List({Number(x), Number(y)}); }

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
Value Ring(const v1::Ring& ring, bool exterior) {
  std::vector<std::pair<double, double>> points;
  for (const v1::Point2& p : ring.points()) points.emplace_back(p.x(), p.y());
  if (!points.empty() && points.front() != points.back()) points.push_back(points.front());
  double twice_area = 0.0;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    twice_area += points[i].first * points[i + 1].second - points[i + 1].first * points[i].second;
  }
  if ((twice_area > 0.0) != exterior) std::reverse(points.begin(), points.end());
  std::vector<Value> positions;
  for (const auto& [x, y] : points) positions.push_back(Position(x, y));
  return List(std::move(positions));
}

Value PolygonGeometry(const v1::Polygon& polygon) {
  std::vector<Value> rings{Ring(polygon.outer(), true)};
  for (const v1::Ring& hole : polygon.holes()) rings.push_back(Ring(hole, false));
  return Geometry("Polygon", List(std::move(rings)));
}

Value PathFeature(const v1::PlanResponse& plan) {
  std::vector<Value> positions, times, headings, kinds, ranks;
  for (const v1::Waypoint& w : plan.path()) {
    positions.push_back(Position(w.x(), w.y()));
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

Value CellCentre(const v1::Grid& grid, const v1::CellRef& cell) {
  return Position(grid.origin_x_m() + (cell.col() + 0.5) * grid.cell_size_m(),
                  grid.origin_y_m() + (cell.row() + 0.5) * grid.cell_size_m());
}

void AddUnitsAndCycles(const v1::PlanResponse& plan, std::vector<Value>* features) {
  for (int i = 0; i < plan.ranks_size(); ++i) {
    const v1::Rank& rank = plan.ranks(i);
    features->push_back(Feature(
        "rank",
        Geometry("LineString", List({CellCentre(plan.grid(), rank.first_cell()),
                                     CellCentre(plan.grid(), rank.last_cell())})),
        {{"index", Number(i)}, {"orientation", Text(v1::Orientation_Name(rank.orientation()))}}));
  }
  for (int c = 0; c < plan.cycles_size(); ++c) {
    const v1::ChargeCycle& cycle = plan.cycles(c);
    std::vector<Value> positions;
    for (int w = std::max(0, cycle.first_waypoint());
         w <= cycle.last_waypoint() && w < plan.path_size(); ++w) {
      positions.push_back(Position(plan.path(w).x(), plan.path(w).y()));
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

absl::StatusOr<std::string> PlanToGeoJson(const v1::PlanResponse& plan) {
  std::vector<Value> features{PathFeature(plan)};
  AddUnitsAndCycles(plan, &features);
  for (const v1::Polygon& zone : plan.regions())
    features.push_back(Feature("region", PolygonGeometry(zone), {}));
  for (const v1::Polygon& zone : plan.no_go())
    features.push_back(Feature("no_go", PolygonGeometry(zone), {}));
  const Value collection =
      Object({{"type", Text("FeatureCollection")}, {"features", List(std::move(features))}});
  return Print(collection.struct_value());
}

std::string PlanToCsv(const v1::PlanResponse& plan) {
  std::string out = "x,y,heading_rad,time_s,kind,rank\n";
  for (const v1::Waypoint& w : plan.path()) {
    absl::StrAppendFormat(&out, "%.17g,%.17g,%.17g,%.17g,%s,%d\n", w.x(), w.y(), w.theta(),
                          w.time_s(), v1::SegmentKind_Name(w.kind()), w.rank());
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
