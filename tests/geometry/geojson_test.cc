// ParseGeoJsonPolygons: every accepted shape, document order, and path-named errors.
#include "api/geojson.h"

#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

constexpr char kSquare[] = R"([[0,0],[4,0],[4,4],[0,4],[0,0]])";
constexpr char kHole[] = R"([[1,1],[1,2],[2,2],[2,1],[1,1]])";

std::string Polygon(const std::string& rings) {
  return R"({"type":"Polygon","coordinates":[)" + rings + "]}";
}

std::vector<PolygonInput> MustParse(const std::string& json) {
  absl::StatusOr<std::vector<PolygonInput>> p = ParseGeoJsonPolygons(json, "site.geojson");
  EXPECT_TRUE(p.ok()) << p.status();
  return p.ok() ? *std::move(p) : std::vector<PolygonInput>();
}

void ExpectError(const std::string& json, const std::string& message, size_t max_bytes = 1 << 20) {
  absl::StatusOr<std::vector<PolygonInput>> p =
      ParseGeoJsonPolygons(json, "site.geojson", max_bytes);
  ASSERT_FALSE(p.ok()) << "accepted: " << json;
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(p.status().message()), HasSubstr(message));
}

TEST(GeoJsonTest, PolygonWithHoleAndThirdCoordinate) {
  const auto p = MustParse(Polygon(std::string(R"([[0,0,7],[4,0,7],[4,4],[0,4],[0,0]],)") + kHole));
  ASSERT_EQ(p.size(), 1u);
  ASSERT_EQ(p[0].outer.size(), 5u);
  EXPECT_EQ(p[0].outer[1].x, 4.0);
  EXPECT_EQ(p[0].outer[1].y, 0.0);
  ASSERT_EQ(p[0].holes.size(), 1u);
  EXPECT_EQ(p[0].holes[0][1].y, 2.0);
  absl::StatusOr<Area> area = Area::Create(p, "site.geojson");
  ASSERT_TRUE(area.ok()) << area.status();
  EXPECT_NEAR(area->AreaM2(), 15.0, 1e-12);
}

TEST(GeoJsonTest, MultiPolygonGeometryCollectionAndFeatures) {
  const std::string multi =
      R"({"type":"MultiPolygon","coordinates":[[[[10,0],[11,0],[11,1],[10,0]]],)"
      R"([[[20,0],[21,0],[21,1],[20,0]]]]})";
  EXPECT_EQ(MustParse(multi).size(), 2u);
  const std::string collection =
      R"({"type":"GeometryCollection","geometries":[)" + Polygon(kSquare) + "," + multi + "]}";
  const auto c = MustParse(collection);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].outer[1].x, 4.0);
  EXPECT_EQ(c[1].outer[0].x, 10.0);
  EXPECT_EQ(c[2].outer[0].x, 20.0);
  const std::string feature =
      R"({"type":"Feature","properties":{"name":"a"},"geometry":)" + collection + "}";
  EXPECT_EQ(MustParse(feature).size(), 3u);
  const std::string features = R"({"type":"FeatureCollection","features":[)"
                               R"({"type":"Feature","geometry":null,"properties":{}},)" +
                               feature + R"(,{"type":"Feature","geometry":)" + Polygon(kHole) +
                               "}]}";
  const auto f = MustParse(features);
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[3].outer[1].y, 2.0);  // document order
}

TEST(GeoJsonTest, RingsPassThroughUnchecked) {
  const auto p = MustParse(Polygon(R"([[0,0],[1,0],[1,1]])"));
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].outer.size(), 3u);
  absl::StatusOr<Area> area = Area::Create(p, "site.geojson");
  EXPECT_THAT(std::string(area.status().message()),
              HasSubstr("site.geojson[0].outer: ring is not closed"));
}

TEST(GeoJsonTest, BadPositionsNamePath) {
  const std::string ok_feature = R"({"type":"Feature","geometry":)" + Polygon(kSquare) + "}";
  const std::string bad_feature =
      R"({"type":"Feature","geometry":{"type":"Polygon","coordinates":[)"
      R"([[0,0],[4,0],[4,4],[0,4],[2,2],[1],[0,0]]]}})";
  ExpectError(R"({"type":"FeatureCollection","features":[)" + ok_feature + "," + ok_feature + "," +
                  bad_feature + "]}",
              "site.geojson: features[2].geometry.coordinates[0][5]: expected a position [x, y] "
              "of numbers");
  ExpectError(Polygon(R"([[0,0],["1",0],[0,0]])"), "site.geojson: coordinates[0][1]: expected a");
  ExpectError(Polygon(R"([[0,0],[1,0,"z"],[0,0]])"), "coordinates[0][1]: expected a position");
  ExpectError(Polygon(R"([[0,0],5,[0,0]])"), "coordinates[0][1]: expected a position");
  ExpectError(Polygon(R"([[0,0],[1,null],[0,0]])"), "coordinates[0][1]: expected a position");
  ExpectError(Polygon(std::string(kSquare) + ",7"), "coordinates[1]: expected a ring");
  ExpectError(R"({"type":"MultiPolygon","coordinates":[[)" + std::string(kSquare) + "],3]}",
              "site.geojson: coordinates[1]: expected a polygon");
  ExpectError(R"({"type":"MultiPolygon","coordinates":[[[[0,0],[1,0],[0,1],{}]]]})",
              "coordinates[0][0][3]: expected a position");
}

TEST(GeoJsonTest, WrongTypesNamePath) {
  ExpectError(R"({"type":"FeatureCollection","features":[{"type":"Feature","geometry":)" +
                  Polygon(kSquare) +
                  R"(},{"type":"Feature","geometry":{"type":"Point","coordinates":[1,2]}}]})",
              "site.geojson: features[1].geometry: geometry type Point is not supported");
  ExpectError(R"({"type":"GeometryCollection","geometries":[)" + Polygon(kSquare) +
                  R"(,{"type":"LineString","coordinates":[[0,0],[1,1]]}]})",
              "site.geojson: geometries[1]: geometry type LineString is not supported");
  ExpectError(R"({"type":"FeatureCollection","features":[)" + Polygon(kSquare) + "]}",
              "features[0]: expected a Feature, got Polygon");
  ExpectError(R"({"type":"Feature","geometry":{"type":"Feature","geometry":null}})",
              "site.geojson: geometry: expected a geometry, got type \"Feature\"");
  ExpectError(R"({"type":"Polygn","coordinates":[]})", "top level: expected a geometry");
  ExpectError(R"({"type":7})", "site.geojson: type: expected a string");
  ExpectError(R"({"coordinates":[]})", "site.geojson: top level: missing member \"type\"");
  ExpectError("[1,2]", "site.geojson: top level: expected a GeoJSON object");
  ExpectError(R"({"type":"Feature"})", "missing member \"geometry\"");
  ExpectError(R"({"type":"Polygon"})", "missing member \"coordinates\"");
  ExpectError(R"({"type":"Polygon","coordinates":{}})", "coordinates: expected an array of rings");
  ExpectError(R"({"type":"Polygon","coordinates":[]})", "coordinates: a Polygon needs at least");
  ExpectError(R"({"type":"FeatureCollection","features":{}})",
              "features: expected an array of Features");
  ExpectError(R"({"type":"FeatureCollection","features":[{"type":"Feature","geometry":5}]})",
              "features[0].geometry: expected a GeoJSON object");
}

TEST(GeoJsonTest, InvalidJsonTooLargeNothingFound) {
  ExpectError(R"({"type":"Polygon",)", "site.geojson: not valid JSON: ");
  ExpectError("", "site.geojson: not valid JSON");
  const std::string square = Polygon(kSquare);
  ExpectError(square, "site.geojson: input is 66 bytes, more than the limit of 65", 65);
  EXPECT_TRUE(ParseGeoJsonPolygons(square, "s", square.size()).ok());
  ExpectError(R"({"type":"FeatureCollection","features":[]})",
              "site.geojson: no Polygon or MultiPolygon found");
  ExpectError(R"({"type":"Feature","geometry":null})", "no Polygon or MultiPolygon found");
  std::string deep = Polygon(kSquare);
  for (int i = 0; i < 9; ++i) deep = R"({"type":"GeometryCollection","geometries":[)" + deep + "]}";
  ExpectError(deep, "geometries[0]: GeometryCollections nested too deeply");
  for (int i = 0; i < 30; ++i)
    deep = R"({"type":"GeometryCollection","geometries":[)" + deep + "]}";
  ExpectError(deep, "site.geojson: not valid JSON: ");  // protobuf's own depth limit
}

}  // namespace
}  // namespace covplan
