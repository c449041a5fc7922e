// The fixture of the mission service tests: a server in process on a
// temporary store with the shipped office stored, three robots planned by
// PlanFleet, and the calls the tests make (UpdateMission, GetMission,
// GetPlan, Drive sessions).
#ifndef COVPLAN_TESTS_SERVER_MISSION_FIXTURE_H_
#define COVPLAN_TESTS_SERVER_MISSION_FIXTURE_H_

#include <grpcpp/grpcpp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"

namespace covplan::testing {

inline std::set<int> SweptCells(const v1::PlanResponse& plan) {
  std::set<int> cells;
  for (const v1::CoverageSweep& s : plan.sweeps()) cells.insert(s.cells().begin(), s.cells().end());
  return cells;
}

class MissionServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_mission_", ::getpid()))
               .string();
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.store_dir = dir_ + "/maps";
    ASSERT_NO_FATAL_FAILURE(StartServer(config));
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
  void StartServer(const ServerConfig& config) {
    config_ = config;
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_->port()), grpc::InsecureChannelCredentials()));
  }
  // Stops the server (its I/O pool finishes its writes) and starts another on
  // the same store.
  void Restart() {
    server_.reset();
    StartServer(config_);
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }

  // Robots a (west end), b (placed by the planner) and c (east end).
  void PlanThree() {
    v1::PlanFleetRequest r;
    r.mutable_plan()->set_map_id(map_id_);
    r.mutable_plan()->mutable_robot()->set_tool_width_m(0.8);
    r.mutable_plan()->set_time_limit_s(1.0);
    const double x[] = {1.5, 0.0, 20.0};
    const char* ids[] = {"a", "b", "c"};
    for (int i = 0; i < 3; ++i) {
      v1::FleetRobot* robot = r.add_robots();
      robot->set_id(ids[i]);
      robot->mutable_robot()->set_tool_width_m(0.8);
      if (i == 1) continue;
      robot->mutable_robot()->mutable_start()->set_x(x[i]);
      robot->mutable_robot()->mutable_start()->set_y(1.5);
    }
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    grpc::Status status = stub_->PlanFleet(&context, r, &fleet_);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_EQ(fleet_.robots_size(), 3);
    for (const v1::FleetRobotPlan& robot : fleet_.robots()) ASSERT_FALSE(robot.idle());
  }
  grpc::Status Update(const v1::UpdateMissionRequest& request, v1::UpdateMissionResponse* out) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->UpdateMission(&context, request, out);
  }
  grpc::Status GetMission(const std::string& mission_id, v1::GetMissionResponse* out) {
    grpc::ClientContext context;
    v1::GetMissionRequest get;
    get.set_mission_id(mission_id);
    return stub_->GetMission(&context, get, out);
  }
  grpc::Status GetPlan(const std::string& plan_id, v1::PlanResponse* out) {
    grpc::ClientContext context;
    v1::GetPlanRequest get;
    get.set_plan_id(plan_id);
    return stub_->GetPlan(&context, get, out);
  }

  // A robot's Drive session on `plan_id`, its ready event read.
  struct Session {
    std::unique_ptr<grpc::ClientContext> context;
    std::unique_ptr<grpc::ClientReaderWriter<v1::DriveRequest, v1::DriveEvent>> stream;
  };
  Session OpenDrive(const std::string& plan_id) {
    Session s;
    s.context = std::make_unique<grpc::ClientContext>();
    s.context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    s.stream = stub_->Drive(s.context.get());
    v1::DriveRequest first;
    first.set_plan_id(plan_id);
    first.set_sequence(1);
    EXPECT_TRUE(s.stream->Write(first));
    v1::DriveEvent ready;
    EXPECT_TRUE(s.stream->Read(&ready));
    EXPECT_TRUE(ready.has_ready()) << ready.DebugString();
    return s;
  }
  static void Close(Session& s) {
    s.stream->WritesDone();
    EXPECT_TRUE(s.stream->Finish().ok());
  }

  ServerConfig config_;
  std::string dir_;
  std::string map_id_;
  std::unique_ptr<CovplanServer> server_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
  v1::PlanFleetResponse fleet_;
};

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_MISSION_FIXTURE_H_
