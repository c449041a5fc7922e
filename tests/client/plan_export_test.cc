// Plans exported as GeoJSON, CSV and nav_msgs/Path JSON (`covplan plan
// --out-*`, `covplan export`), read back and checked against the plan: RFC
// 7946's rules, the path vertex for vertex with its times and headings, unit
// quaternions of the headings, and clear errors for bad use.
#include <google/protobuf/struct.pb.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/plan_command.h"
#include "client/plan_exports.h"
#include "gmock/gmock.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

using google::protobuf::Struct;
using google::protobuf::Value;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const Value& Field(const Value& v, const std::string& key) {
  static const Value kNull;
  const auto& fields = v.struct_value().fields();
  auto it = fields.find(key);
  return it == fields.end() ? kNull : it->second;
}

Value ParseJson(const std::string& text) {
  Value v;
  EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(text, &v).ok()) << text.substr(0, 200);
  return v;
}

// Twice the signed area of a closed ring of [x, y] positions (> 0: counter-clockwise).
double TwiceSignedArea(const Value& ring) {
  const auto& p = ring.list_value().values();
  double sum = 0.0;
  for (int i = 0; i + 1 < p.size(); ++i) {
    sum +=
        p[i].list_value().values(0).number_value() *
            p[i + 1].list_value().values(1).number_value() -
        p[i + 1].list_value().values(0).number_value() * p[i].list_value().values(1).number_value();
  }
  return sum;
}

class PlanExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_export_", ::getpid()))
               .string();
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  // The shipped yard with a clockwise no-go ring and a battery, planned locally.
  v1::PlanResponse PlanYard(const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"--map",
                                     absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_yard.geojson"),
                                     "--local",
                                     "--tool-width",
                                     "0.6",
                                     "--tour",
                                     "greedy",
                                     "--no-go",
                                     "10,5 10,6.5 12,6.5 12,5",
                                     "--battery-capacity",
                                     "400",
                                     "--station",
                                     "1,1",
                                     "--out",
                                     Path("plan.json")};
    args.insert(args.end(), extra.begin(), extra.end());
    EXPECT_EQ(RunPlanCommand(args), 0);
    v1::PlanResponse plan;
    EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(Read(Path("plan.json")), &plan).ok());
    return plan;
  }
  std::string dir_;
};

TEST_F(PlanExportTest, GeoJsonFollowsRfc7946AndCarriesThePathWithTimesAndHeadings) {
  const v1::PlanResponse plan = PlanYard({"--out-geojson", Path("plan.geojson")});
  ASSERT_GT(plan.cycles_size(), 1);
  const Value doc = ParseJson(Read(Path("plan.geojson")));
  EXPECT_EQ(Field(doc, "type").string_value(), "FeatureCollection");
  int ranks = 0, cycles = 0, no_go = 0;
  for (const Value& f : Field(doc, "features").list_value().values()) {
    EXPECT_EQ(Field(f, "type").string_value(), "Feature");
    const Value& geometry = Field(f, "geometry");
    const Value& props = Field(f, "properties");
    const std::string kind = Field(props, "feature").string_value();
    if (kind == "path") {
      ASSERT_EQ(Field(geometry, "type").string_value(), "LineString");
      const auto& positions = Field(geometry, "coordinates").list_value().values();
      const auto& times = Field(props, "times_s").list_value().values();
      const auto& headings = Field(props, "headings_rad").list_value().values();
      ASSERT_EQ(positions.size(), plan.path_size());
      ASSERT_EQ(times.size(), plan.path_size());
      for (int i = 0; i < plan.path_size(); ++i) {
        ASSERT_EQ(positions[i].list_value().values_size(), 2);  // [x, y]: x first
        EXPECT_EQ(positions[i].list_value().values(0).number_value(), plan.path(i).x());
        EXPECT_EQ(positions[i].list_value().values(1).number_value(), plan.path(i).y());
        EXPECT_EQ(headings[i].number_value(), plan.path(i).theta());
        EXPECT_EQ(times[i].number_value(), plan.path(i).time_s());
        if (i > 0) {
          EXPECT_GE(times[i].number_value(), times[i - 1].number_value());
        }
      }
      EXPECT_NEAR(times[times.size() - 1].number_value(), plan.stats().estimated_duration_s(),
                  1e-6 * plan.stats().estimated_duration_s());
    } else if (kind == "rank") {
      EXPECT_EQ(Field(geometry, "type").string_value(), "LineString");
      ++ranks;
    } else if (kind == "cycle") {
      EXPECT_EQ(Field(props, "energy").number_value(), plan.cycles(cycles).energy());
      ++cycles;
    } else if (kind == "no_go") {
      ASSERT_EQ(Field(geometry, "type").string_value(), "Polygon");
      const Value& outer = Field(geometry, "coordinates").list_value().values(0);
      const auto& p = outer.list_value().values();
      ASSERT_GE(p.size(), 4);
      EXPECT_EQ(p[0].list_value().values(0).number_value(),
                p[p.size() - 1].list_value().values(0).number_value());  // closed
      EXPECT_EQ(p[0].list_value().values(1).number_value(),
                p[p.size() - 1].list_value().values(1).number_value());
      // Given clockwise on the command line, written counter-clockwise.
      EXPECT_GT(TwiceSignedArea(outer), 0.0);
      ++no_go;
    }
  }
  EXPECT_EQ(ranks, plan.ranks_size());
  EXPECT_EQ(cycles, plan.cycles_size());
  EXPECT_EQ(no_go, 1);
}

TEST_F(PlanExportTest, CsvReadsBackToTheSamePath) {
  const v1::PlanResponse plan = PlanYard({"--out-csv", Path("plan.csv")});
  const std::vector<std::string> lines =
      absl::StrSplit(Read(Path("plan.csv")), '\n', absl::SkipEmpty());
  ASSERT_EQ(lines.size(), plan.path_size() + 1u);
  EXPECT_EQ(lines[0], "x,y,heading_rad,time_s,kind,rank");
  for (int i = 0; i < plan.path_size(); ++i) {
    const std::vector<std::string> cells = absl::StrSplit(lines[i + 1], ',');
    ASSERT_EQ(cells.size(), 6u);
    const v1::Waypoint& w = plan.path(i);
    EXPECT_EQ(std::strtod(cells[0].c_str(), nullptr), w.x());
    EXPECT_EQ(std::strtod(cells[1].c_str(), nullptr), w.y());
    EXPECT_EQ(std::strtod(cells[2].c_str(), nullptr), w.theta());
    EXPECT_EQ(std::strtod(cells[3].c_str(), nullptr), w.time_s());
    EXPECT_EQ(cells[4], v1::SegmentKind_Name(w.kind()));
    EXPECT_EQ(std::atoi(cells[5].c_str()), w.rank());
  }
}

TEST_F(PlanExportTest, NavPathHasUnitQuaternionsOfTheHeadingsAndTimedStamps) {
  const v1::PlanResponse plan = PlanYard(
      {"--out-nav-path", Path("path.json"), "--frame-id", "odom", "--nav-stamp", "1700000000.25"});
  const Value doc = ParseJson(Read(Path("path.json")));
  EXPECT_EQ(Field(Field(doc, "header"), "frame_id").string_value(), "odom");
  const auto& poses = Field(doc, "poses").list_value().values();
  ASSERT_EQ(poses.size(), plan.path_size());
  for (int i = 0; i < plan.path_size(); ++i) {
    const Value& q = Field(Field(poses[i], "pose"), "orientation");
    const double x = Field(q, "x").number_value(), y = Field(q, "y").number_value();
    const double z = Field(q, "z").number_value(), w = Field(q, "w").number_value();
    EXPECT_NEAR(x * x + y * y + z * z + w * w, 1.0, 1e-12);
    const double yaw = std::atan2(2.0 * w * z, 1.0 - 2.0 * z * z);
    EXPECT_NEAR(std::remainder(yaw - plan.path(i).theta(), 2.0 * M_PI), 0.0, 1e-9);
    const Value& position = Field(Field(poses[i], "pose"), "position");
    EXPECT_EQ(Field(position, "x").number_value(), plan.path(i).x());
    const Value& stamp = Field(Field(poses[i], "header"), "stamp");
    const double t =
        Field(stamp, "sec").number_value() + 1e-9 * Field(stamp, "nanosec").number_value();
    EXPECT_NEAR(t, 1700000000.25 + plan.path(i).time_s(), 2e-6);
    EXPECT_LT(Field(stamp, "nanosec").number_value(), 1e9);
  }
}

TEST_F(PlanExportTest, NavPathWithoutAStartStampLeavesEveryStampUnset) {
  PlanYard({"--out-nav-path", Path("path.json")});
  const Value doc = ParseJson(Read(Path("path.json")));
  for (const Value& pose : Field(doc, "poses").list_value().values()) {
    const Value& stamp = Field(Field(pose, "header"), "stamp");
    EXPECT_EQ(Field(stamp, "sec").number_value(), 0);
    EXPECT_EQ(Field(stamp, "nanosec").number_value(), 0);
  }
}

TEST_F(PlanExportTest, ExportCommandReadsPlansAndFleetsAndRefusesBadUse) {
  PlanYard({"--out-csv", Path("direct.csv")});
  ASSERT_EQ(RunExportCommand({"--plan", Path("plan.json"), "--out-csv", Path("again.csv")}), 0);
  EXPECT_EQ(Read(Path("again.csv")), Read(Path("direct.csv")));

  const std::string office = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml");
  ASSERT_EQ(RunPlanCommand({"--map", office, "--local", "--tool-width", "0.8", "--time-limit",
                            "0.3", "--robot", "west=1.5,1.5", "--robot", "east=20,1.5", "--out",
                            Path("fleet.json")}),
            0);
  ASSERT_EQ(RunExportCommand(
                {"--plan", Path("fleet.json"), "--robot", "east", "--out-csv", Path("east.csv")}),
            0);
  // The file holds east's own plan: it starts where east starts.
  const std::vector<std::string> east = absl::StrSplit(Read(Path("east.csv")), '\n');
  ASSERT_GT(east.size(), 2u);
  EXPECT_THAT(east[1], ::testing::StartsWith("20,1.5,")) << east[1];
  // A fleet needs --robot; unknown robots, missing exports, bad files are errors.
  EXPECT_NE(RunExportCommand({"--plan", Path("fleet.json"), "--out-csv", Path("x.csv")}), 0);
  EXPECT_NE(RunExportCommand(
                {"--plan", Path("fleet.json"), "--robot", "north", "--out-csv", Path("x.csv")}),
            0);
  EXPECT_NE(RunExportCommand({"--plan", Path("plan.json")}), 0);
  EXPECT_NE(RunExportCommand({"--plan", Path("direct.csv"), "--out-csv", Path("x.csv")}), 0);
  EXPECT_NE(RunExportCommand({"--plan", Path("plan.json"), "--frame-id", "map"}), 0);
  // A plan whose waypoints carry no times (written before they did) is refused, not
  // exported with zeros.
  v1::PlanResponse untimed;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(Read(Path("plan.json")), &untimed).ok());
  for (v1::Waypoint& w : *untimed.mutable_path()) w.clear_time_s();
  std::string text;
  ASSERT_TRUE(google::protobuf::util::MessageToJsonString(untimed, &text).ok());
  std::ofstream(Path("untimed.json")) << text;
  EXPECT_NE(RunExportCommand({"--plan", Path("untimed.json"), "--out-csv", Path("x.csv")}), 0);
  // Exports of a fleet plan must go through covplan export.
  EXPECT_NE(RunPlanCommand(
                {"--map", office, "--local", "--robot", "a=1.5,1.5", "--out-csv", Path("x.csv")}),
            0);
  EXPECT_FALSE(std::filesystem::exists(Path("x.csv")));
}

}  // namespace
}  // namespace covplan
