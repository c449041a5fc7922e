// The PlanFleet RPC in process: two robots on the shipped office map get
// two retained plans (GetPlan returns them, Replan continues one, and after
// a restart the stored ones are found again) that together sweep every cell
// the single-robot Plan sweeps, a Drive session continues one, the mission
// is kept; more robots than work on an inline map
// leaves some idle, whose plans are retained but not replanned; bad fleets
// are INVALID_ARGUMENT naming the field.
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/plan_checks.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

std::set<int> SweptCells(const v1::PlanResponse& plan) {
  std::set<int> cells;
  for (const v1::CoverageSweep& s : plan.sweeps()) cells.insert(s.cells().begin(), s.cells().end());
  return cells;
}

v1::FleetRobot* AddRobot(v1::PlanFleetRequest* request, const std::string& id, double tool,
                         double x, double y) {
  v1::FleetRobot* robot = request->add_robots();
  robot->set_id(id);
  robot->mutable_robot()->set_tool_width_m(tool);
  robot->mutable_robot()->mutable_start()->set_x(x);
  robot->mutable_robot()->mutable_start()->set_y(y);
  return robot;
}

class FleetServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_fleet_", ::getpid()))
               .string();
    Start();
    absl::StatusOr<v1::Map> map =
        MapProtoFromFile(absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml"),
                         MapFileOverrides(), EngineLimits());
    ASSERT_TRUE(map.ok()) << map.status();
    grpc::ClientContext context;
    v1::PutMapRequest put;
    *put.mutable_map() = *map;
    v1::PutMapResponse stored;
    ASSERT_TRUE(stub_->PutMap(&context, put, &stored).ok());
    map_id_ = stored.map_id();
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }
  void Start() {
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.store_dir = dir_ + "/maps";
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_->port()), grpc::InsecureChannelCredentials()));
  }
  v1::PlanRequest Base() const {
    v1::PlanRequest r;
    r.set_map_id(map_id_);
    r.mutable_robot()->set_tool_width_m(0.8);
    r.set_time_limit_s(0.5);
    return r;
  }
  // Two robots at the office's west and east ends.
  v1::PlanFleetRequest TwoRobots() const {
    v1::PlanFleetRequest r;
    *r.mutable_plan() = Base();
    AddRobot(&r, "west", 0.8, 1.5, 1.5);
    AddRobot(&r, "east", 0.8, 20.0, 1.5);
    return r;
  }
  grpc::Status PlanFleet(const v1::PlanFleetRequest& request, v1::PlanFleetResponse* out) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->PlanFleet(&context, request, out);
  }
  grpc::Status Plan(const v1::PlanRequest& request, v1::PlanResponse* out) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->Plan(&context, request, out);
  }
  grpc::Status GetPlan(const std::string& plan_id, v1::PlanResponse* out) {
    grpc::ClientContext context;
    v1::GetPlanRequest get;
    get.set_plan_id(plan_id);
    return stub_->GetPlan(&context, get, out);
  }
  grpc::Status Replan(const v1::ReplanRequest& request, v1::ReplanResponse* out) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->Replan(&context, request, out);
  }
  // The robot a sixth of the way along its plan; the first cell its last
  // sweep covers is reported blocked.
  static v1::ReplanRequest ObstacleAhead(const v1::PlanResponse& plan) {
    v1::ReplanRequest r;
    r.set_plan_id(plan.plan_id());
    const int k = std::max(1, plan.path_size() / 6);
    r.mutable_progress()->set_waypoint(k);
    r.mutable_progress()->mutable_position()->set_x(plan.path(k - 1).x());
    r.mutable_progress()->mutable_position()->set_y(plan.path(k - 1).y());
    const int cell = plan.sweeps(plan.sweeps_size() - 1).cells(0);
    v1::CellRef* blocked = r.mutable_obstacles()->add_cells();
    blocked->set_row(cell / plan.grid().cols());
    blocked->set_col(cell % plan.grid().cols());
    return r;
  }
  grpc::Status Refusal(const v1::PlanFleetRequest& request) {
    v1::PlanFleetResponse out;
    return PlanFleet(request, &out);
  }

  std::string dir_;
  std::string map_id_;
  std::unique_ptr<CovplanServer> server_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(FleetServiceTest, TwoRobotsGetRetainedPlansThatCoverWhatOnePlanCovers) {
  v1::PlanFleetResponse fleet;
  grpc::Status status = PlanFleet(TwoRobots(), &fleet);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(absl::StartsWith(fleet.mission_id(), "mission-")) << fleet.mission_id();
  ASSERT_EQ(fleet.robots_size(), 2);
  EXPECT_EQ(fleet.robots(0).id(), "west");
  EXPECT_EQ(fleet.robots(1).id(), "east");
  EXPECT_EQ(fleet.division(), v1::FLEET_DIVISION_MAKESPAN);
  EXPECT_EQ(fleet.covered_cells(), fleet.cover_cells());
  EXPECT_GT(fleet.makespan_s(), 0.0);
  EXPECT_GE(fleet.makespan_s(), fleet.lower_bound_s());
  EXPECT_GT(fleet.safety().clearance_m(), 0.0);
  const v1::PlanResponse& a = fleet.robots(0).plan();
  const v1::PlanResponse& b = fleet.robots(1).plan();
  EXPECT_FALSE(a.plan_id().empty());
  EXPECT_NE(a.plan_id(), b.plan_id());
  EXPECT_NE(a.plan_id(), fleet.mission_id());
  EXPECT_EQ(a.map_id(), map_id_);
  for (const v1::FleetRobotPlan& robot : fleet.robots()) {
    EXPECT_FALSE(robot.idle());
    EXPECT_GT(robot.assigned_cells(), 0);
    v1::PlanResponse retained;
    status = GetPlan(robot.plan().plan_id(), &retained);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(retained.SerializeAsString(), robot.plan().SerializeAsString());
    testing::ExpectArrivalTimes(robot.plan());
  }

  // Together the robots sweep every cell the single-robot plan sweeps.
  v1::PlanResponse single;
  status = Plan(Base(), &single);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(single.grid().rows(), a.grid().rows());
  ASSERT_EQ(single.grid().cols(), a.grid().cols());
  std::set<int> together = SweptCells(a);
  for (int cell : SweptCells(b)) together.insert(cell);
  const std::set<int> alone = SweptCells(single);
  EXPECT_EQ(static_cast<int>(together.size()), fleet.covered_cells());
  for (int cell : alone) EXPECT_TRUE(together.count(cell)) << "cell " << cell << " swept by none";
  EXPECT_GE(together.size(), alone.size());

  // A robot's plan is continued like any plan.
  v1::ReplanResponse replanned;
  status = Replan(ObstacleAhead(b), &replanned);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(replanned.replan().newly_blocked_cells(), 0);
  EXPECT_NE(replanned.plan().plan_id(), b.plan_id());
  testing::ExpectArrivalTimes(replanned.plan());
  EXPECT_EQ(static_cast<int>(SweptCells(replanned.plan()).size()),
            replanned.replan().remaining_cells());
  // Nothing of the other robot's share was added to it.
  const std::set<int> own = SweptCells(b);
  for (int cell : SweptCells(replanned.plan())) EXPECT_TRUE(own.count(cell)) << cell;
}

TEST_F(FleetServiceTest, TheMissionIsKeptAndARobotPlanIsDriven) {
  v1::PlanFleetResponse fleet;
  grpc::Status status = PlanFleet(TwoRobots(), &fleet);
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::optional<FleetMission> mission = server_->service().missions().Get(fleet.mission_id());
  ASSERT_TRUE(mission.has_value());
  EXPECT_EQ(mission->map_id, map_id_);
  EXPECT_EQ(mission->robot_ids, (std::vector<std::string>{"west", "east"}));
  EXPECT_EQ(mission->plan_ids, (std::vector<std::string>{fleet.robots(0).plan().plan_id(),
                                                         fleet.robots(1).plan().plan_id()}));

  // A Drive session on the west robot's plan: an observation gets a new plan.
  const v1::PlanResponse& plan = fleet.robots(0).plan();
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientReaderWriter<v1::DriveRequest, v1::DriveEvent>> stream =
      stub_->Drive(&context);
  v1::DriveRequest first;
  first.set_plan_id(plan.plan_id());
  first.set_sequence(1);
  ASSERT_TRUE(stream->Write(first));
  v1::DriveEvent event;
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_ready()) << event.DebugString();
  const v1::ReplanRequest seen = ObstacleAhead(plan);
  v1::DriveRequest observation;
  observation.set_sequence(2);
  *observation.mutable_progress() = seen.progress();
  *observation.mutable_obstacles() = seen.obstacles();
  ASSERT_TRUE(stream->Write(observation));
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_replan()) << event.DebugString();
  EXPECT_EQ(event.sequence(), 2u);
  EXPECT_EQ(static_cast<int>(SweptCells(event.replan().plan()).size()),
            event.replan().replan().remaining_cells());
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

TEST_F(FleetServiceTest, StoredRobotPlansAreReplannedAfterARestart) {
  v1::PlanFleetResponse fleet;
  grpc::Status status = PlanFleet(TwoRobots(), &fleet);
  ASSERT_TRUE(status.ok()) << status.error_message();
  server_.reset();  // the I/O pool finishes its writes on shutdown
  Start();
  for (const v1::FleetRobotPlan& robot : fleet.robots()) {
    v1::ReplanResponse replanned;
    status = Replan(ObstacleAhead(robot.plan()), &replanned);
    ASSERT_TRUE(status.ok()) << robot.id() << ": " << status.error_message();
    EXPECT_EQ(static_cast<int>(SweptCells(replanned.plan()).size()),
              replanned.replan().remaining_cells());
  }
}

TEST_F(FleetServiceTest, IdleRobotsGetPlansThatAreNotReplanned) {
  v1::PlanFleetRequest request;
  *request.mutable_plan()->mutable_map() =
      testing::RasterMap(testing::AsciiToPgm(testing::TwoRooms(), 4), 0.1);
  request.mutable_plan()->mutable_robot()->set_tool_width_m(0.4);
  request.mutable_plan()->set_time_limit_s(1.0);
  for (int i = 0; i < 24; ++i) {
    v1::FleetRobot* robot = request.add_robots();
    robot->set_id(absl::StrCat("r", i));
    robot->mutable_robot()->set_tool_width_m(0.4);
  }
  v1::PlanFleetResponse fleet;
  grpc::Status status = PlanFleet(request, &fleet);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(fleet.robots_size(), 24);
  EXPECT_EQ(fleet.covered_cells(), fleet.cover_cells());
  std::set<std::string> ids;
  int idle = 0;
  for (const v1::FleetRobotPlan& robot : fleet.robots()) {
    ids.insert(robot.plan().plan_id());
    v1::PlanResponse retained;
    ASSERT_TRUE(GetPlan(robot.plan().plan_id(), &retained).ok()) << robot.id();
    if (!robot.idle()) continue;
    ++idle;
    EXPECT_EQ(robot.assigned_cells(), 0);
    EXPECT_EQ(robot.plan().sweeps_size(), 0);
    v1::ReplanRequest replan;
    replan.set_plan_id(robot.plan().plan_id());
    replan.mutable_progress()->set_distance_m(0);
    replan.mutable_obstacles()->add_cells()->set_row(1);
    v1::ReplanResponse out;
    EXPECT_EQ(Replan(replan, &out).error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    grpc::ClientContext context;
    v1::ResumeRequest resume;
    resume.set_plan_id(robot.plan().plan_id());
    resume.mutable_pose()->set_x(1.0);
    resume.mutable_pose()->set_y(1.0);
    EXPECT_EQ(stub_->Resume(&context, resume, &out).error_code(),
              grpc::StatusCode::FAILED_PRECONDITION);
  }
  EXPECT_EQ(ids.size(), 24u);
  EXPECT_GT(idle, 0);
}

// Random plausible fleets on a small inline map (every planner, both
// divisions, starts anywhere including walls, some battery robots): each is
// planned or refused as INVALID_ARGUMENT, and a plan covers every cell.
TEST_F(FleetServiceTest, RandomFleetsArePlannedOrRefusedNeverFailed) {
  std::mt19937 rng(5);
  auto uniform = [&rng](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  const char* planners[] = {"oarp", "stc", "boustrophedon"};
  std::map<std::string, int> outcomes;
  for (int trial = 0; trial < 36; ++trial) {
    v1::PlanFleetRequest request;
    *request.mutable_plan()->mutable_map() =
        testing::RasterMap(testing::AsciiToPgm(testing::TwoRooms(), 4), 0.1);
    request.mutable_plan()->set_planner(planners[trial % 3]);
    request.mutable_plan()->set_time_limit_s(0.3);
    request.mutable_plan()->set_seed(trial);
    request.set_division(trial % 2 == 0 ? v1::FLEET_DIVISION_MAKESPAN
                                        : v1::FLEET_DIVISION_EQUAL_AREA);
    const int k = 1 + static_cast<int>(uniform(0, 5));
    for (int i = 0; i < k; ++i) {
      v1::FleetRobot* robot =
          AddRobot(&request, absl::StrCat("r", i), 0.4, uniform(0, 4.8), uniform(0, 3.2));
      if (uniform(0, 1) < 0.3) robot->mutable_robot()->clear_start();
      if (uniform(0, 1) < 0.3) {
        robot->mutable_robot()->mutable_end()->set_x(uniform(0, 4.8));
        robot->mutable_robot()->mutable_end()->set_y(uniform(0, 3.2));
      }
      if (uniform(0, 1) < 0.2) {
        robot->mutable_battery()->set_capacity(uniform(5, 40));
        robot->mutable_battery()->mutable_station()->set_x(0.6);
        robot->mutable_battery()->mutable_station()->set_y(0.6);
        robot->set_recharge_s(uniform(0, 100));
      }
    }
    v1::PlanFleetResponse fleet;
    const grpc::Status status = PlanFleet(request, &fleet);
    ++outcomes[absl::StrCat(planners[trial % 3], " ", status.error_code())];
    if (!status.ok()) {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
          << "trial " << trial << ": " << status.error_message();
      continue;
    }
    ASSERT_EQ(fleet.robots_size(), k) << "trial " << trial;
    EXPECT_EQ(fleet.covered_cells(), fleet.cover_cells()) << "trial " << trial;
    std::set<int> together;
    for (const v1::FleetRobotPlan& robot : fleet.robots()) {
      const std::set<int> cells = SweptCells(robot.plan());
      together.insert(cells.begin(), cells.end());
    }
    EXPECT_EQ(static_cast<int>(together.size()), fleet.covered_cells()) << "trial " << trial;
  }
  for (const auto& [key, n] : outcomes) std::cout << "  " << key << ": " << n << "\n";
}

TEST_F(FleetServiceTest, BadFleetsAreInvalidArgumentNamingTheField) {
  struct Case {
    std::string name;
    v1::PlanFleetRequest request;
    std::string field;
  };
  std::vector<Case> cases;
  {
    v1::PlanFleetRequest r;
    *r.mutable_plan() = Base();
    cases.push_back({"no robots", r, "robots: a fleet plan needs at least one robot"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_robots(1)->set_id("west");
    cases.push_back({"duplicate ids", r, "robots[1].id"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_robots(1)->mutable_robot()->set_tool_width_m(0.5);
    cases.push_back({"two tool widths", r, "robots[1].robot.tool_width_m"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_robots(0)->mutable_robot()->set_tool_width_m(0);
    cases.push_back({"no tool", r, "robots[0].robot.tool_width_m"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_robots(1)->mutable_battery()->set_capacity(100);
    cases.push_back({"battery without station", r, "robots[1].battery.station"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_robots(1)->set_id("");
    cases.push_back({"empty id", r, "robots[1].id"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_plan()->set_time_limit_s(-1);
    cases.push_back({"base time limit", r, "plan.time_limit_s"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.set_division(static_cast<v1::FleetDivision>(7));
    cases.push_back({"division", r, "division: unknown value 7"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.set_clearance_m(-2);
    cases.push_back({"clearance", r, "clearance_m"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_robots(0)->set_recharge_s(-1);
    cases.push_back({"recharge", r, "robots[0].recharge_s"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_plan()->set_planner("nonesuch");
    cases.push_back({"planner", r, "planner: unknown planner 'nonesuch'"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    for (int i = 0; i < 70; ++i) AddRobot(&r, absl::StrCat("extra", i), 0.8, 1.5, 1.5);
    cases.push_back({"too many robots", r, "robots: at most 64 robots"});
  }
  {
    v1::PlanFleetRequest r = TwoRobots();
    r.mutable_plan()->clear_map_id();
    cases.push_back({"no map", r, "needs map_id or an inline map"});
  }
  for (const Case& c : cases) {
    const grpc::Status status = Refusal(c.request);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.name;
    EXPECT_THAT(status.error_message(), HasSubstr(c.field)) << c.name;
  }
  // An unknown map is NOT_FOUND, as for Plan.
  v1::PlanFleetRequest unknown = TwoRobots();
  unknown.mutable_plan()->set_map_id(std::string(64, 'a'));
  EXPECT_EQ(Refusal(unknown).error_code(), grpc::StatusCode::NOT_FOUND);
}

}  // namespace
}  // namespace covplan
