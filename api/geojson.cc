#include "api/geojson.h"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

using google::protobuf::ListValue;
using google::protobuf::Struct;
using google::protobuf::Value;

// GeometryCollections inside GeometryCollections; RFC 7946 discourages nesting at all. (The
// protobuf parser itself stops at about 50 levels of JSON nesting.)
constexpr int kMaxNesting = 8;

class GeoJsonReader {
 public:
  explicit GeoJsonReader(std::string_view source) : source_(source) {}

  // A top-level GeoJSON object of any accepted type.
  absl::Status ReadDocument(const Value& v) {
    std::string type;
    RETURN_IF_ERROR(ReadType(v, "", type));
    if (type == "FeatureCollection") return ReadFeatureCollection(v.struct_value(), "");
    if (type == "Feature") return ReadFeature(v.struct_value(), "");
    return ReadGeometry(v, "", 0);
  }

  std::vector<PolygonInput> TakePolygons() { return std::move(polygons_); }

 private:
  absl::Status Error(const std::string& path, std::string_view what) const {
    return absl::InvalidArgumentError(
        absl::StrCat(source_, ": ", path.empty() ? "top level" : path, ": ", std::string(what)));
  }

  static std::string Member(const std::string& path, std::string_view name) {
    return path.empty() ? std::string(name) : absl::StrCat(path, ".", std::string(name));
  }

  static std::string Index(const std::string& path, int i) {
    return absl::StrCat(path, "[", i, "]");
  }

  // The member `name` of object `s`, or nullptr.
  static const Value* Find(const Struct& s, const std::string& name) {
    auto it = s.fields().find(name);
    return it == s.fields().end() ? nullptr : &it->second;
  }

  absl::Status ReadType(const Value& v, const std::string& path, std::string& type) const {
    if (!v.has_struct_value()) return Error(path, "expected a GeoJSON object");
    const Value* t = Find(v.struct_value(), "type");
    if (t == nullptr) return Error(path, "missing member \"type\"");
    if (!t->has_string_value()) return Error(Member(path, "type"), "expected a string");
    type = t->string_value();
    return absl::OkStatus();
  }

  // The array member `name` of `s`.
  absl::Status ArrayMember(const Struct& s, const std::string& path, const std::string& name,
                           std::string_view what, const ListValue*& out) const {
    const Value* v = Find(s, name);
    if (v == nullptr) return Error(path, absl::StrFormat("missing member \"%s\"", name));
    if (!v->has_list_value())
      return Error(Member(path, name), absl::StrCat("expected ", std::string(what)));
    out = &v->list_value();
    return absl::OkStatus();
  }

  absl::Status ReadFeatureCollection(const Struct& s, const std::string& path) {
    const ListValue* features = nullptr;
    RETURN_IF_ERROR(ArrayMember(s, path, "features", "an array of Features", features));
    for (int i = 0; i < features->values_size(); ++i) {
      const std::string p = Index(Member(path, "features"), i);
      std::string type;
      RETURN_IF_ERROR(ReadType(features->values(i), p, type));
      if (type != "Feature") return Error(p, absl::StrFormat("expected a Feature, got %s", type));
      RETURN_IF_ERROR(ReadFeature(features->values(i).struct_value(), p));
    }
    return absl::OkStatus();
  }

  absl::Status ReadFeature(const Struct& s, const std::string& path) {
    const Value* geometry = Find(s, "geometry");
    if (geometry == nullptr) return Error(path, "missing member \"geometry\"");
    if (geometry->has_null_value()) return absl::OkStatus();  // an unlocated feature
    return ReadGeometry(*geometry, Member(path, "geometry"), 0);
  }

  absl::Status ReadGeometry(const Value& v, const std::string& path, int depth) {
    std::string type;
    RETURN_IF_ERROR(ReadType(v, path, type));
    const Struct& s = v.struct_value();
    if (type == "GeometryCollection") {
      if (depth >= kMaxNesting) return Error(path, "GeometryCollections nested too deeply");
      const ListValue* geometries = nullptr;
      RETURN_IF_ERROR(ArrayMember(s, path, "geometries", "an array of geometries", geometries));
      for (int i = 0; i < geometries->values_size(); ++i) {
        RETURN_IF_ERROR(
            ReadGeometry(geometries->values(i), Index(Member(path, "geometries"), i), depth + 1));
      }
      return absl::OkStatus();
    }
    if (type != "Polygon" && type != "MultiPolygon") {
      const bool geometry = type == "Point" || type == "MultiPoint" || type == "LineString" ||
                            type == "MultiLineString";
      return Error(path, geometry ? absl::StrFormat("geometry type %s is not supported; expected "
                                                    "Polygon or MultiPolygon",
                                                    type)
                                  : absl::StrFormat("expected a geometry, got type \"%s\"", type));
    }
    const ListValue* coordinates = nullptr;
    const std::string cpath = Member(path, "coordinates");
    if (type == "Polygon") {
      RETURN_IF_ERROR(ArrayMember(s, path, "coordinates", "an array of rings", coordinates));
      return ReadPolygon(*coordinates, cpath);
    }
    RETURN_IF_ERROR(ArrayMember(s, path, "coordinates", "an array of polygons", coordinates));
    for (int i = 0; i < coordinates->values_size(); ++i) {
      const Value& polygon = coordinates->values(i);
      if (!polygon.has_list_value()) {
        return Error(Index(cpath, i), "expected a polygon (an array of rings)");
      }
      RETURN_IF_ERROR(ReadPolygon(polygon.list_value(), Index(cpath, i)));
    }
    return absl::OkStatus();
  }

  absl::Status ReadPolygon(const ListValue& rings, const std::string& path) {
    if (rings.values_size() == 0) return Error(path, "a Polygon needs at least its outer ring");
    PolygonInput polygon;
    for (int i = 0; i < rings.values_size(); ++i) {
      std::vector<Point2>& ring = i == 0 ? polygon.outer : polygon.holes.emplace_back();
      RETURN_IF_ERROR(ReadRing(rings.values(i), Index(path, i), ring));
    }
    polygons_.push_back(std::move(polygon));
    return absl::OkStatus();
  }

  absl::Status ReadRing(const Value& v, const std::string& path, std::vector<Point2>& ring) const {
    if (!v.has_list_value()) return Error(path, "expected a ring (an array of positions)");
    const ListValue& positions = v.list_value();
    ring.reserve(positions.values_size());
    for (int i = 0; i < positions.values_size(); ++i) {
      const Value& p = positions.values(i);
      bool ok = p.has_list_value() && p.list_value().values_size() >= 2;
      for (int k = 0; ok && k < p.list_value().values_size(); ++k) {
        ok = p.list_value().values(k).has_number_value();
      }
      if (!ok) return Error(Index(path, i), "expected a position [x, y] of numbers");
      ring.push_back(
          Point2{p.list_value().values(0).number_value(), p.list_value().values(1).number_value()});
    }
    return absl::OkStatus();
  }

  std::string source_;
  std::vector<PolygonInput> polygons_;
};

}  // namespace

absl::StatusOr<std::vector<PolygonInput>> ParseGeoJsonPolygons(std::string_view json,
                                                               std::string_view source,
                                                               size_t max_bytes) {
  if (json.size() > max_bytes) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: input is %d bytes, more than the limit of %d", source, json.size(), max_bytes));
  }
  Value root;
  const auto parsed = google::protobuf::util::JsonStringToMessage(
      google::protobuf::StringPiece(json.data(), json.size()), &root);
  if (!parsed.ok()) {
    std::string message(parsed.message());
    // What protobuf 3.21 says when the binary re-parse hits its recursion limit of 100
    // messages, i.e. about 50 nested JSON arrays/objects.
    if (message == "JSON transcoder produced invalid protobuf output.") {
      message += " (nested too deeply?)";
    }
    return absl::InvalidArgumentError(
        absl::StrCat(std::string(source), ": not valid JSON: ", message));
  }
  GeoJsonReader reader(source);
  RETURN_IF_ERROR(reader.ReadDocument(root));
  std::vector<PolygonInput> polygons = reader.TakePolygons();
  if (polygons.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(std::string(source), ": no Polygon or MultiPolygon found"));
  }
  return polygons;
}

}  // namespace covplan
