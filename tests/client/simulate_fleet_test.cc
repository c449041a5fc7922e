// `covplan simulate --robot ... --fail-robot ID@SECONDS` (client/simulate_fleet.h):
// a fleet of three on the shipped office driving the furnished one, one robot
// failing, with the summary, the JSON and the SVG; --fail-robot parsed and
// bad values refused naming the flag.
#include "client/simulate_fleet.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "planner/plan/fleet_svg.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

std::string MapPath(const std::string& name) {
  return std::string(COVPLAN_SOURCE_DIR) + "/maps/" + name;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

absl::StatusOr<std::string> Simulate(const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"--map",        MapPath("small_rooms.yaml"),
                                   "--true-map",   MapPath("small_rooms.yaml"),
                                   "--time-limit", "0.3",
                                   "--tool-width", "0.8"};
  args.insert(args.end(), extra.begin(), extra.end());
  return SimulateCommandJson(args, nullptr, &FleetSimulation());
}

TEST(FailRobotFlag, IsIdAtSeconds) {
  absl::StatusOr<RobotFailure> f = ParseFailRobot("b@12.5");
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(f->robot_id, "b");
  EXPECT_EQ(f->time_s, 12.5);
  f = ParseFailRobot("dock@2@0");  // the last '@' separates the time
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(f->robot_id, "dock@2");
  EXPECT_EQ(f->time_s, 0.0);
  for (const char* bad : {"nope", "@3", "a@", "a@-1", "a@inf", "a@nan", "a@3s", ""}) {
    absl::StatusOr<RobotFailure> r = ParseFailRobot(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_THAT(r.status().message(), HasSubstr("--fail-robot must be ID@SECONDS")) << bad;
    EXPECT_THAT(r.status().message(), HasSubstr(absl::StrCat("got '", bad, "'")));
  }
}

TEST(SimulateFleetCommand, BadFleetValuesAreRefusedNamingTheFlag) {
  auto refused = [](const std::vector<std::string>& extra) {
    absl::StatusOr<std::string> r = Simulate(extra);
    EXPECT_FALSE(r.ok());
    return std::string(r.status().message());
  };
  EXPECT_THAT(refused({"--robot", "1.2,1.2", "--fail-robot", "nope"}),
              HasSubstr("--fail-robot must be ID@SECONDS (a robot's id and the simulated time it "
                        "fails at, seconds >= 0), got 'nope'"));
  EXPECT_THAT(refused({"--fail-robot", "nope"}), HasSubstr("got 'nope'"));
  EXPECT_THAT(refused({"--fail-robot", "r1@3"}), HasSubstr("give --robot X,Y"));
  EXPECT_THAT(refused({"--robots", "2", "--fail-robot", "r3@3"}),
              HasSubstr("--fail-robot: no robot 'r3' in the fleet (its robots: r1, r2)"));
  EXPECT_THAT(refused({"--robots", "2", "--fail-robot", "r1@3", "--fail-robot", "r1@4"}),
              HasSubstr("--fail-robot: robot 'r1' fails twice"));
  EXPECT_THAT(refused({"--robot", "1,x"}), HasSubstr("--robot"));
  EXPECT_THAT(refused({"--robots", "2", "--battery-capacity", "100", "--station", "1.2,1.2"}),
              HasSubstr("no battery"));
  // Without the fleet hook the fleet flags are not simulate's.
  absl::StatusOr<std::string> plain =
      SimulateCommandJson({"--map", MapPath("small_rooms.yaml"), "--true-map",
                           MapPath("small_rooms.yaml"), "--robot", "1.2,1.2"});
  EXPECT_FALSE(plain.ok());
}

TEST(SimulateFleetCommand, ThreeRobotsOneFailingPrintWriteAndDraw) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_simfleet_", ::getpid()))
          .string();
  std::filesystem::create_directories(dir);
  const std::vector<std::string> args = {"--map",        MapPath("sample_office.yaml"),
                                         "--true-map",   MapPath("sample_office_furnished.yaml"),
                                         "--time-limit", "0.5",
                                         "--tool-width", "0.8",
                                         "--robot",      "a=1.5,1.5",
                                         "--robot",      "b=20,1.5",
                                         "--robot",      "c=10,10",
                                         "--fail-robot", "b@150",
                                         "--out",        dir + "/run.json",
                                         "--svg",        dir + "/run.svg"};
  absl::StatusOr<std::string> summary = SimulateCommandJson(args, nullptr, &FleetSimulation());
  ASSERT_TRUE(summary.ok()) << summary.status();
  std::printf("%s\n", summary->c_str());
  EXPECT_THAT(*summary, HasSubstr("fleet      3 robots"));
  EXPECT_THAT(*summary, HasSubstr("failed, stopped at"));
  EXPECT_THAT(*summary, HasSubstr("failure    b at 150.0 s"));
  EXPECT_THAT(*summary, HasSubstr("redivided among a, c"));
  EXPECT_THAT(*summary, HasSubstr("unswept    0 reachable cells"));

  google::protobuf::Struct json;
  const std::string text = ReadFile(dir + "/run.json");
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(text, &json).ok()) << text;
  const auto& f = json.fields();
  EXPECT_EQ(f.at("unswept_reachable_cells").number_value(), 0);
  EXPECT_GT(f.at("makespan_s").number_value(), 150.0);
  const auto& redivisions = f.at("redivisions").list_value().values();
  ASSERT_EQ(redivisions.size(), 1);
  const auto& d = redivisions[0].struct_value().fields();
  EXPECT_EQ(d.at("failed_robot").string_value(), "b");
  EXPECT_GT(d.at("estimated_makespan_s").number_value(), 0.0);
  EXPECT_NEAR(d.at("achieved_s").number_value(), f.at("makespan_s").number_value() - 150.0, 1e-5);
  const auto& robots = f.at("robots").list_value().values();
  ASSERT_EQ(robots.size(), 3);
  EXPECT_TRUE(robots[1].struct_value().fields().at("failed").bool_value());
  EXPECT_LE(robots[1].struct_value().fields().at("finish_s").number_value(), 150.0 + 1e-6);
  EXPECT_EQ(robots[0].struct_value().fields().at("legs").list_value().values_size(), 2);

  const std::string picture = ReadFile(dir + "/run.svg");
  EXPECT_THAT(picture, HasSubstr("</svg>"));
  for (size_t i = 0; i < 3; ++i)
    EXPECT_THAT(picture, HasSubstr(absl::StrCat("stroke=\"", FleetSvgColour(i), "\"")));
  EXPECT_THAT(picture, HasSubstr("b (failed)"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace covplan
