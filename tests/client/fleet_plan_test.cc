// `covplan plan --local --robot ... --robot ...` (client/fleet_plan.h): a
// fleet of robots on a shipped map, the fleet JSON (each robot's plan in
// plan.json's form) sweeping every cell the single plan sweeps, the SVG with
// one colour per robot, and bad fleet flags refused naming the flag.
#include "client/fleet_plan.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "client/plan_command.h"
#include "gmock/gmock.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "planner/plan/fleet_svg.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct FleetJson {
  google::protobuf::Struct top;
  std::vector<std::string> ids;
  std::vector<v1::PlanResponse> plans;
};

// The fleet JSON, with each robot's plan parsed back as a PlanResponse.
FleetJson ReadFleetJson(const std::string& path) {
  FleetJson f;
  const std::string text = ReadFile(path);
  EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(text, &f.top).ok()) << text;
  const auto& robots = f.top.fields().at("robots").list_value();
  for (const google::protobuf::Value& robot : robots.values()) {
    const auto& fields = robot.struct_value().fields();
    f.ids.push_back(fields.at("id").string_value());
    std::string plan_json;
    EXPECT_TRUE(google::protobuf::util::MessageToJsonString(fields.at("plan"), &plan_json).ok());
    v1::PlanResponse plan;
    EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(plan_json, &plan).ok());
    f.plans.push_back(plan);
  }
  return f;
}

class FleetPlanCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_fleet_", ::getpid()))
               .string();
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // `covplan plan --local` on small_rooms with a 0.8 m tool and 1 s.
  std::vector<std::string> Args(const std::vector<std::string>& extra) const {
    std::vector<std::string> args = {"--map", map_,           "--local", "--tool-width",
                                     "0.8",   "--time-limit", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  // The exit code is non-zero and stderr names `flag`.
  void ExpectRefused(const std::vector<std::string>& extra, const std::string& flag) {
    SCOPED_TRACE(absl::StrCat("refused: ", flag));
    ::testing::internal::CaptureStderr();
    const int rc = RunPlanCommand(Args(extra));
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(rc, 0);
    EXPECT_THAT(err, HasSubstr(flag));
  }

  std::string map_ = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml");
  std::string dir_;
};

TEST_F(FleetPlanCommandTest, TwoRobotsSweepEveryCellAndEachGetsItsColour) {
  const std::string single = dir_ + "/single.json", out = dir_ + "/fleet.json",
                    svg = dir_ + "/fleet.svg";
  ASSERT_EQ(RunPlanCommand(Args({"--out", single})), 0);
  v1::PlanResponse one;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(ReadFile(single), &one).ok());
  ASSERT_GT(one.stats().free_cells(), 0);

  ::testing::internal::CaptureStdout();
  const int rc = RunPlanCommand(
      Args({"--robot", "1.2,1.2", "--robot", "east=8.4,6,1.57", "--out", out, "--svg", svg}));
  const std::string summary = ::testing::internal::GetCapturedStdout();
  ASSERT_EQ(rc, 0);
  EXPECT_THAT(summary, HasSubstr("fleet      2 robots"));
  EXPECT_THAT(summary, HasSubstr("makespan"));
  EXPECT_THAT(summary, HasSubstr("lower bound"));
  EXPECT_THAT(summary, HasSubstr("closest approach"));

  const FleetJson f = ReadFleetJson(out);
  ASSERT_EQ(f.plans.size(), 2u);
  EXPECT_EQ(f.ids, (std::vector<std::string>{"r1", "east"}));
  EXPECT_EQ(f.top.fields().at("division").string_value(), "makespan");
  EXPECT_GT(f.top.fields().at("makespan_s").number_value(), 0.0);
  EXPECT_EQ(f.top.fields().at("covered_cells").number_value(),
            f.top.fields().at("cover_cells").number_value());
  int64_t swept = 0;
  double makespan = 0.0;
  for (size_t i = 0; i < f.plans.size(); ++i) {
    SCOPED_TRACE(f.ids[i]);
    const v1::PlanResponse& p = f.plans[i];
    EXPECT_GT(p.stats().covered_cells(), 0);  // no robot empty
    ASSERT_GT(p.path_size(), 2);
    swept += p.stats().covered_cells();
    makespan = std::max(makespan, p.stats().estimated_duration_s());
    // Without --end each robot returns to its own start.
    const v1::Waypoint& s = p.path(0);
    const v1::Waypoint& e = p.path(p.path_size() - 1);
    EXPECT_NEAR(s.x(), i == 0 ? 1.2 : 8.4, 1e-9);
    EXPECT_NEAR(s.y(), i == 0 ? 1.2 : 6.0, 1e-9);
    EXPECT_NEAR(e.x(), s.x(), 1e-9);
    EXPECT_NEAR(e.y(), s.y(), 1e-9);
  }
  EXPECT_GE(swept, one.stats().free_cells());
  EXPECT_NEAR(f.top.fields().at("makespan_s").number_value(), makespan, 1e-6);

  const std::string picture = ReadFile(svg);
  EXPECT_THAT(picture, HasSubstr("</svg>"));
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_THAT(picture, HasSubstr(absl::StrCat("stroke=\"", FleetSvgColour(i), "\"")));
  }
  EXPECT_NE(std::string(FleetSvgColour(0)), FleetSvgColour(1));
  EXPECT_THAT(picture, HasSubstr(">east</tspan>"));
}

TEST_F(FleetPlanCommandTest, RobotsWithoutStartsAndTheEqualAreaDivision) {
  const std::string out = dir_ + "/fleet.json";
  ::testing::internal::CaptureStdout();
  const int rc = RunPlanCommand(Args({"--robots", "3", "--division", "equal_area", "--clearance",
                                      "0.5", "--planner", "boustrophedon", "--out", out}));
  const std::string summary = ::testing::internal::GetCapturedStdout();
  ASSERT_EQ(rc, 0);
  EXPECT_THAT(summary, HasSubstr("division equal_area"));
  const FleetJson f = ReadFleetJson(out);
  EXPECT_EQ(f.ids, (std::vector<std::string>{"r1", "r2", "r3"}));
  EXPECT_EQ(f.top.fields().at("division").string_value(), "equal_area");
  EXPECT_DOUBLE_EQ(
      f.top.fields().at("safety").struct_value().fields().at("clearance_m").number_value(), 0.5);
  for (const v1::PlanResponse& p : f.plans) EXPECT_EQ(p.planner(), "boustrophedon");
}

TEST_F(FleetPlanCommandTest, BadFleetFlagsAreRefusedNamingTheFlag) {
  ExpectRefused({"--robot", "1,x"}, "--robot");
  ExpectRefused({"--robot", "1"}, "--robot");
  ExpectRefused({"--robot", "=1,1"}, "--robot");
  ExpectRefused({"--robot", "a=1,1", "--robot", "a=2,2"}, "--robot");
  ExpectRefused({"--robots", "2", "--division", "nope"},
                "--division must be makespan or equal_area");
  ExpectRefused({"--robots", "0"}, "--robots");
  ExpectRefused({"--robots", "two"}, "--robots");
  ExpectRefused({"--robots", "2", "--robot", "1,1"}, "--robots");
  ExpectRefused({"--robots", "2", "--clearance", "-1"}, "--clearance");
  ExpectRefused({"--division", "makespan"}, "--division");
  ExpectRefused({"--robot", "1.2,1.2", "--start", "2,2"}, "--start");
  // Without --local the fleet goes to the server, which says when it is away.
  ::testing::internal::CaptureStderr();
  EXPECT_NE(RunPlanCommand({"--map", map_, "--robots", "2", "--server", "127.0.0.1:1"}), 0);
  EXPECT_THAT(::testing::internal::GetCapturedStderr(), HasSubstr("server 127.0.0.1:1 replied"));
}

// --end applies to every robot; without it each keeps the model's default
// (back to its own start); the battery and robot model are shared.
TEST(FleetFlags, MakeFleetRequestSharesTheModelAndKeepsEachStart) {
  ParsedArgs a;
  a.repeated[kRobotFlag] = {"1,2", "dock=3,4,0.5"};
  absl::StatusOr<std::optional<FleetFlags>> flags = ParseFleetFlags(a);
  ASSERT_TRUE(flags.ok()) << flags.status();
  ASSERT_TRUE(flags->has_value());
  PlanRequest base;
  base.common.robot.tool_width_m = 0.6;
  base.common.robot.max_speed_mps = 0.7;
  FleetRequest request = MakeFleetRequest(base, **flags);
  ASSERT_EQ(request.robots.size(), 2u);
  EXPECT_EQ(request.robots[1].id, "dock");
  EXPECT_EQ(request.robots[1].robot.start->theta, 0.5);
  EXPECT_EQ(request.robots[0].robot.tool_width_m, 0.6);
  EXPECT_EQ(request.robots[1].robot.max_speed_mps, 0.7);
  // Without --end the model's default: back to the robot's own start.
  EXPECT_FALSE(request.robots[1].robot.end.has_value());
  EXPECT_TRUE(request.Validate().ok());
  base.common.robot.end = Pose2{5, 5, 0};
  request = MakeFleetRequest(base, **flags);
  for (const FleetRobot& r : request.robots) EXPECT_EQ(r.robot.end->x, 5.0);
  // --robots K: no start (the planner places them), each with the battery.
  ParsedArgs spread;
  spread.values["robots"] = "2";
  absl::StatusOr<std::optional<FleetFlags>> k = ParseFleetFlags(spread);
  ASSERT_TRUE(k.ok() && k->has_value());
  base.common.robot.end.reset();
  base.battery = BatteryOptions();
  request = MakeFleetRequest(base, **k);
  ASSERT_EQ(request.robots.size(), 2u);
  EXPECT_EQ(request.robots[1].id, "r2");
  EXPECT_FALSE(request.robots[1].robot.start.has_value());
  EXPECT_FALSE(request.robots[1].robot.end.has_value());
  EXPECT_TRUE(request.robots[1].battery.has_value());

  ParsedArgs none;
  absl::StatusOr<std::optional<FleetFlags>> no_fleet = ParseFleetFlags(none);
  ASSERT_TRUE(no_fleet.ok());
  EXPECT_FALSE(no_fleet->has_value());
}

}  // namespace
}  // namespace covplan
