// The Drive streaming session and the Resume RPC, in process: a plan pushed
// after an observation, a newer observation superseding an older replan,
// bounded sessions, idle sessions ended, a vanished client freed, bad
// messages answered without ending the session, and resuming from where the
// robot stopped (given, recorded by a session, and recorded across a
// restart).
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "client/simulate_command.h"
#include "client/simulate_remote.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/plan_checks.h"

namespace covplan {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;

using Stream = grpc::ClientReaderWriter<v1::DriveRequest, v1::DriveEvent>;

class DriveSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_drive_", ::getpid()))
               .string();
    absl::StatusOr<v1::Map> map =
        MapProtoFromFile(absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml"),
                         MapFileOverrides(), EngineLimits());
    ASSERT_TRUE(map.ok()) << map.status();
    map_ = *map;
  }
  void TearDown() override {
    stub_.reset();
    server_.reset();
    std::filesystem::remove_all(dir_);
  }
  void Start(int max_sessions = 8, absl::Duration idle = absl::Seconds(60)) {
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.store_dir = dir_ + "/maps";
    config.service.max_sessions = max_sessions;
    config.service.session_idle = idle;
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_->port()), grpc::InsecureChannelCredentials()));
  }
  // A plan on the stored office map (so it is persisted).
  v1::PlanResponse PlanOffice() {
    v1::PutMapRequest put;
    *put.mutable_map() = map_;
    v1::PutMapResponse stored;
    {
      grpc::ClientContext context;
      EXPECT_TRUE(stub_->PutMap(&context, put, &stored).ok());
    }
    v1::PlanRequest r;
    r.set_map_id(stored.info().map_id());
    r.mutable_robot()->set_tool_width_m(0.8);
    r.set_time_limit_s(0.3);
    v1::PlanResponse plan;
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    const grpc::Status status = stub_->Plan(&context, r, &plan);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return plan;
  }
  static v1::RobotProgress At(const v1::PlanResponse& plan, int k) {
    v1::RobotProgress p;
    p.set_waypoint(k);
    p.mutable_position()->set_x(plan.path(k - 1).x());
    p.mutable_position()->set_y(plan.path(k - 1).y());
    return p;
  }
  static void AddBox(double x0, double y0, double x1, double y1, v1::Obstacles* o) {
    v1::Ring* ring = o->add_polygons()->mutable_outer();
    for (auto [x, y] : {std::pair{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}}) {
      v1::Point2* p = ring->add_points();
      p->set_x(x);
      p->set_y(y);
    }
  }
  static int Swept(const v1::PlanResponse& plan) {
    std::set<int> cells;
    for (const v1::CoverageSweep& s : plan.sweeps())
      cells.insert(s.cells().begin(), s.cells().end());
    return static_cast<int>(cells.size());
  }
  static bool CellFree(const v1::PlanResponse& plan, double x, double y) {
    const v1::Grid& g = plan.grid();
    const int c = static_cast<int>(std::floor((x - g.origin_x_m()) / g.cell_size_m()));
    const int r = static_cast<int>(std::floor((y - g.origin_y_m()) / g.cell_size_m()));
    return g.free_cells(r)[c] == '1';
  }
  // Opens a session on `plan_id` and reads its ready event.
  std::unique_ptr<Stream> Open(grpc::ClientContext* context, const std::string& plan_id,
                               v1::ReplanMethod method = v1::AUTO) {
    std::unique_ptr<Stream> stream = stub_->Drive(context);
    v1::DriveRequest first;
    first.set_plan_id(plan_id);
    first.set_method(method);
    first.set_sequence(1);
    EXPECT_TRUE(stream->Write(first));
    v1::DriveEvent ready;
    EXPECT_TRUE(stream->Read(&ready));
    EXPECT_TRUE(ready.has_ready()) << ready.DebugString();
    EXPECT_EQ(ready.ready().plan_id(), plan_id);
    EXPECT_EQ(ready.sequence(), 1u);
    return stream;
  }
  bool WaitForSessions(int n) {
    for (int i = 0; i < 500; ++i) {
      if (server_->service().sessions().size() == n) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  std::string dir_;
  v1::Map map_;
  std::unique_ptr<CovplanServer> server_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(DriveSessionTest, PushesAPlanAfterAnObservation) {
  Start();
  const v1::PlanResponse plan = PlanOffice();
  grpc::ClientContext context;
  std::unique_ptr<Stream> stream = Open(&context, plan.plan_id());
  // A progress report alone pushes nothing; the observation does.
  const int k = plan.path_size() / 6;
  v1::DriveRequest report;
  report.set_sequence(2);
  *report.mutable_progress() = At(plan, k - 1 > 0 ? k - 1 : 1);
  ASSERT_TRUE(stream->Write(report));
  v1::DriveRequest seen;
  seen.set_sequence(3);
  *seen.mutable_progress() = At(plan, k);
  AddBox(9.0, 9.2, 10.2, 10.0, seen.mutable_obstacles());
  ASSERT_TRUE(stream->Write(seen));
  v1::DriveEvent event;
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_replan()) << event.DebugString();
  EXPECT_EQ(event.sequence(), 3u);
  const v1::ReplanResponse r = event.replan();
  EXPECT_GT(r.replan().newly_blocked_cells(), 0);
  EXPECT_EQ(Swept(r.plan()), r.replan().remaining_cells());
  testing::ExpectArrivalTimes(r.plan());  // a plan the session pushed
  EXPECT_NEAR(r.plan().path(0).x(), seen.progress().position().x(), 1e-9);
  EXPECT_FALSE(CellFree(r.plan(), 9.6, 9.6));
  // The pushed plan is retained and named in the next message.
  v1::DriveRequest next;
  next.set_sequence(4);
  next.set_plan_id(r.plan().plan_id());
  *next.mutable_progress() = At(r.plan(), 2);
  next.mutable_obstacles()->add_points()->set_x(r.plan().path(r.plan().path_size() / 2).x());
  next.mutable_obstacles()->mutable_points(0)->set_y(r.plan().path(r.plan().path_size() / 2).y());
  ASSERT_TRUE(stream->Write(next));
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_replan()) << event.DebugString();
  EXPECT_EQ(event.sequence(), 4u);
  EXPECT_EQ(Swept(event.replan().plan()), event.replan().replan().remaining_cells());
  EXPECT_LT(event.replan().replan().remaining_cells(), r.replan().remaining_cells());
  // The earlier box is still known to the newer plan.
  EXPECT_FALSE(CellFree(event.replan().plan(), 9.6, 9.6));
  stream->WritesDone();
  EXPECT_FALSE(stream->Read(&event));
  const grpc::Status status = stream->Finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(WaitForSessions(0));
}

TEST_F(DriveSessionTest, ANewerObservationSupersedesAnUnfinishedReplan) {
  Start();
  const v1::PlanResponse plan = PlanOffice();
  grpc::ClientContext context;
  // FULL replans take about a second (the tour search's limit): the second
  // observation surely arrives while the first is still running.
  std::unique_ptr<Stream> stream = Open(&context, plan.plan_id(), v1::FULL);
  const int k = plan.path_size() / 6;
  v1::DriveRequest a;
  a.set_sequence(2);
  *a.mutable_progress() = At(plan, k);
  AddBox(9.0, 9.2, 10.2, 10.0, a.mutable_obstacles());
  v1::DriveRequest b;
  b.set_sequence(3);
  *b.mutable_progress() = At(plan, k);
  AddBox(4.0, 4.0, 4.9, 4.9, b.mutable_obstacles());
  ASSERT_TRUE(stream->Write(a));
  ASSERT_TRUE(stream->Write(b));
  v1::DriveEvent event;
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_replan()) << event.DebugString();
  // The first event answers the newest observation and names the older one.
  EXPECT_EQ(event.sequence(), 3u);
  EXPECT_THAT(event.superseded(), Contains(2u));
  // Both observations' obstacles are in the plan.
  EXPECT_FALSE(CellFree(event.replan().plan(), 9.6, 9.6));
  EXPECT_FALSE(CellFree(event.replan().plan(), 4.4, 4.4));
  EXPECT_EQ(Swept(event.replan().plan()), event.replan().replan().remaining_cells());
  stream->WritesDone();
  EXPECT_FALSE(stream->Read(&event));  // no event for the superseded observation
  EXPECT_TRUE(stream->Finish().ok());
}

TEST_F(DriveSessionTest, BadMessagesGetErrorEventsAndTheSessionGoesOn) {
  Start();
  const v1::PlanResponse plan = PlanOffice();
  grpc::ClientContext context;
  std::unique_ptr<Stream> stream = Open(&context, plan.plan_id());
  const int k = plan.path_size() / 6;
  struct Case {
    v1::DriveRequest request;
    const char* message;
  };
  std::vector<Case> cases;
  v1::DriveRequest r;
  r.set_sequence(10);
  *r.mutable_progress() = At(plan, k);
  r.mutable_obstacles()->add_points()->set_x(std::nan(""));
  cases.push_back({r, "obstacles.points[0]"});
  r = v1::DriveRequest();
  r.set_sequence(11);
  *r.mutable_progress() = At(plan, k);
  r.mutable_obstacles()->add_cells()->set_row(100000);
  cases.push_back({r, "obstacles.cells[0]"});
  r = v1::DriveRequest();
  r.set_sequence(12);
  r.set_plan_id("p-not-of-this-session");
  r.mutable_obstacles()->add_cells()->set_row(1);
  cases.push_back({r, "not a plan of this session"});
  r = v1::DriveRequest();
  r.set_sequence(13);
  r.mutable_progress()->set_waypoint(plan.path_size() + 9);
  r.mutable_progress()->mutable_position()->set_x(1);
  AddBox(9.0, 9.2, 10.2, 10.0, r.mutable_obstacles());
  cases.push_back({r, "progress.waypoint"});
  for (const Case& c : cases) {
    ASSERT_TRUE(stream->Write(c.request));
    v1::DriveEvent event;
    ASSERT_TRUE(stream->Read(&event));
    ASSERT_TRUE(event.has_error()) << event.DebugString();
    EXPECT_EQ(event.sequence(), c.request.sequence());
    EXPECT_EQ(event.error().code(), static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
    EXPECT_THAT(event.error().message(), HasSubstr(c.message));
  }
  // The bad observations left nothing behind: a good one is replanned.
  v1::DriveRequest good;
  good.set_sequence(20);
  *good.mutable_progress() = At(plan, k);
  AddBox(9.0, 9.2, 10.2, 10.0, good.mutable_obstacles());
  ASSERT_TRUE(stream->Write(good));
  v1::DriveEvent event;
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_replan()) << event.DebugString();
  EXPECT_EQ(event.sequence(), 20u);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

TEST_F(DriveSessionTest, AFirstMessageWithoutAKnownPlanEndsTheSession) {
  Start();
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> stream = stub_->Drive(&context);
    v1::DriveRequest first;
    first.mutable_obstacles()->add_cells();
    ASSERT_TRUE(stream->Write(first));
    v1::DriveEvent event;
    EXPECT_FALSE(stream->Read(&event));
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("plan_id or an inline plan"));
  }
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> stream = stub_->Drive(&context);
    v1::DriveRequest first;
    first.set_plan_id("p-unknown");
    ASSERT_TRUE(stream->Write(first));
    v1::DriveEvent event;
    EXPECT_FALSE(stream->Read(&event));
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  }
  EXPECT_TRUE(WaitForSessions(0));
}

TEST_F(DriveSessionTest, SessionsAreBoundedInNumber) {
  Start(/*max_sessions=*/1);
  const v1::PlanResponse plan = PlanOffice();
  grpc::ClientContext first_context;
  std::unique_ptr<Stream> first = Open(&first_context, plan.plan_id());
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> second = stub_->Drive(&context);
    v1::DriveEvent event;
    EXPECT_FALSE(second->Read(&event));
    const grpc::Status status = second->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_THAT(status.error_message(), HasSubstr("--max_sessions"));
  }
  first->WritesDone();
  EXPECT_TRUE(first->Finish().ok());
  ASSERT_TRUE(WaitForSessions(0));
  grpc::ClientContext context;
  std::unique_ptr<Stream> again = Open(&context, plan.plan_id());
  again->WritesDone();
  EXPECT_TRUE(again->Finish().ok());
}

TEST_F(DriveSessionTest, AnIdleSessionIsEnded) {
  Start(/*max_sessions=*/4, /*idle=*/absl::Milliseconds(300));
  const v1::PlanResponse plan = PlanOffice();
  grpc::ClientContext context;
  std::unique_ptr<Stream> stream = Open(&context, plan.plan_id());
  v1::DriveEvent event;
  EXPECT_FALSE(stream->Read(&event));  // blocks until the server ends it
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_THAT(status.error_message(), HasSubstr("idle"));
  EXPECT_TRUE(WaitForSessions(0));
}

TEST_F(DriveSessionTest, AClientThatGoesAwayFreesItsSession) {
  Start();
  const v1::PlanResponse plan = PlanOffice();
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> stream = Open(&context, plan.plan_id(), v1::FULL);
    v1::DriveRequest seen;
    seen.set_sequence(2);
    *seen.mutable_progress() = At(plan, plan.path_size() / 6);
    AddBox(9.0, 9.2, 10.2, 10.0, seen.mutable_obstacles());
    ASSERT_TRUE(stream->Write(seen));
    EXPECT_EQ(server_->service().sessions().size(), 1);
    context.TryCancel();  // mid-replan
    stream->Finish().IgnoreError();
  }
  EXPECT_TRUE(WaitForSessions(0));
  // The server still serves.
  EXPECT_FALSE(PlanOffice().plan_id().empty());
}

TEST_F(DriveSessionTest, ResumeContinuesFromWhereTheRobotStopped) {
  Start();
  const v1::PlanResponse plan = PlanOffice();
  const int k = plan.path_size() / 3;
  const v1::Pose dock = [&] {
    v1::Pose p;
    p.set_x(plan.path(0).x());
    p.set_y(plan.path(0).y());
    return p;
  }();
  auto resume = [&](const v1::ResumeRequest& request, v1::ReplanResponse* out) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->Resume(&context, request, out);
  };
  // Nothing recorded: from the plan's start, nothing counted as covered.
  v1::ResumeRequest request;
  request.set_plan_id(plan.plan_id());
  *request.mutable_pose() = dock;
  v1::ReplanResponse fresh;
  ASSERT_TRUE(resume(request, &fresh).ok());
  EXPECT_EQ(fresh.replan().progress_source(), "plan_start");
  // (At most the cell it starts in: a tool-width robot on a cell's centre
  // covers that cell.)
  EXPECT_LE(fresh.replan().covered_cells_before(), 1);
  EXPECT_EQ(fresh.replan().covered_cells_before() + fresh.replan().remaining_cells(), Swept(plan));
  // Given progress: back from the dock to the stop point, then the rest
  // (and the progress is recorded).
  *request.mutable_progress() = At(plan, k);
  v1::ReplanResponse given;
  grpc::Status status = resume(request, &given);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(given.replan().progress_source(), "request");
  EXPECT_NEAR(given.plan().path(0).x(), dock.x(), 1e-9);
  EXPECT_NEAR(given.plan().path(0).y(), dock.y(), 1e-9);
  EXPECT_GT(given.replan().rejoin_m(), 0.0);
  EXPECT_GT(given.replan().covered_cells_before(), 0);
  EXPECT_EQ(Swept(given.plan()), given.replan().remaining_cells());
  EXPECT_EQ(given.replan().covered_cells_before() + given.replan().remaining_cells(), Swept(plan));
  testing::ExpectArrivalTimes(given.plan());
  // A session's progress report is recorded, and survives a restart.
  request.clear_progress();
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> stream = Open(&context, plan.plan_id());
    v1::DriveRequest report;
    report.set_sequence(2);
    *report.mutable_progress() = At(plan, 2 * k);  // farther than the last Resume
    ASSERT_TRUE(stream->Write(report));
    stream->WritesDone();
    EXPECT_TRUE(stream->Finish().ok());
  }
  v1::ReplanResponse recorded;
  ASSERT_TRUE(resume(request, &recorded).ok());
  EXPECT_EQ(recorded.replan().progress_source(), "recorded");
  EXPECT_GT(recorded.replan().covered_cells_before(), given.replan().covered_cells_before());
  server_.reset();  // the drain flushes the I/O pool
  Start();
  v1::ReplanResponse restarted;
  status = resume(request, &restarted);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(restarted.replan().progress_source(), "recorded");
  EXPECT_EQ(restarted.replan().covered_cells_before(), recorded.replan().covered_cells_before());
  EXPECT_EQ(Swept(restarted.plan()), restarted.replan().remaining_cells());
  // Bad input names the field.
  v1::ResumeRequest bad = request;
  bad.mutable_pose()->set_x(std::nan(""));
  v1::ReplanResponse out;
  status = resume(bad, &out);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("pose"));
  bad = request;
  bad.mutable_pose()->set_x(-500);
  status = resume(bad, &out);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("pose"));
  bad = request;
  bad.clear_pose();
  status = resume(bad, &out);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  bad = request;
  bad.set_plan_id("p-nope");
  status = resume(bad, &out);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
}

// Identical Plan calls are missions of their own, also when the second and
// later ones are answered from memory: each gets its own plan id, and the
// progress one robot reports is not what Resume reads for another, also
// after a restart (a repeated hit's id is stored, as a record naming the
// first hit's plan, when it is first used or else by the drain, and is
// rebuilt from it).
TEST_F(DriveSessionTest, IdenticalPlanCallsAreMissionsOfTheirOwn) {
  Start();
  std::vector<v1::PlanResponse> plans;
  for (int i = 0; i < 5; ++i) plans.push_back(PlanOffice());
  ASSERT_EQ(plans[1].stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);  // the first hit
  ASSERT_EQ(plans[2].stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  ASSERT_EQ(plans[3].stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  std::set<std::string> ids;
  for (const v1::PlanResponse& p : plans) ids.insert(p.plan_id());
  EXPECT_EQ(ids.size(), 5u);
  const v1::PlanResponse& driven = plans[2];
  const int k = driven.path_size() / 2;
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> stream = Open(&context, driven.plan_id());
    v1::DriveRequest report;
    report.set_sequence(2);
    *report.mutable_progress() = At(driven, k);
    ASSERT_TRUE(stream->Write(report));
    stream->WritesDone();
    EXPECT_TRUE(stream->Finish().ok());
  }
  const auto resume = [&](const std::string& plan_id) {
    v1::ResumeRequest request;
    request.set_plan_id(plan_id);
    request.mutable_pose()->set_x(driven.path(0).x());
    request.mutable_pose()->set_y(driven.path(0).y());
    v1::ReplanResponse out;
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    const grpc::Status status = stub_->Resume(&context, request, &out);
    EXPECT_TRUE(status.ok()) << plan_id << ": " << status.error_message();
    return std::pair{out.replan().progress_source(), out.replan().covered_cells_before()};
  };
  const auto [source, covered] = resume(driven.plan_id());
  EXPECT_EQ(source, "recorded");
  EXPECT_GT(covered, 1);
  // Nothing covered but the cell the robot starts in.
  const int at_start = resume(plans[1].plan_id()).second;
  EXPECT_LE(at_start, 1);
  EXPECT_EQ(resume(plans[3].plan_id()), std::pair(std::string("plan_start"), at_start));
  // (Resume records where it resumed from: the start, for 1 and 3.)
  server_.reset();  // the drain flushes the I/O pool
  Start();
  EXPECT_EQ(resume(driven.plan_id()), std::pair(std::string("recorded"), covered));
  EXPECT_EQ(resume(plans[0].plan_id()), std::pair(std::string("plan_start"), at_start));
  for (int i : {1, 3}) {
    EXPECT_EQ(resume(plans[i].plan_id()), std::pair(std::string("recorded"), at_start)) << i;
  }
  // Never used before the restart: stored by the drain.
  EXPECT_EQ(resume(plans[4].plan_id()), std::pair(std::string("plan_start"), at_start));
  // Rebuilt by the Resume above: the first hit's plan under its own id.
  v1::GetPlanRequest get;
  get.set_plan_id(plans[3].plan_id());
  v1::PlanResponse again;
  grpc::ClientContext context;
  ASSERT_TRUE(stub_->GetPlan(&context, get, &again).ok());
  EXPECT_EQ(again.plan_id(), plans[3].plan_id());
  ASSERT_EQ(again.path_size(), plans[1].path_size());
  for (int i = 0; i < again.path_size(); ++i) {
    EXPECT_EQ(again.path(i).x(), plans[1].path(i).x());
    EXPECT_EQ(again.path(i).y(), plans[1].path(i).y());
  }
}

// `covplan simulate --server`: the whole run through one Drive session.
TEST_F(DriveSessionTest, TheSimulatorDrivesThroughASession) {
  Start();
  const std::vector<std::string> args = {
      "--map",
      absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml"),
      "--clutter",
      "5",
      "--seed",
      "3",
      "--time-limit",
      "0.3",
      "--replan-tour-limit",
      "0.3",
      "--no-offline-bound",
      "--server",
      absl::StrCat("127.0.0.1:", server_->port())};
  absl::StatusOr<std::string> json = SimulateCommandJson(args, &ConnectServerPlanSource);
  ASSERT_TRUE(json.ok()) << json.status();
  EXPECT_THAT(*json, HasSubstr("\"planner_at\": \"server 127.0.0.1:"));
  EXPECT_THAT(*json, HasSubstr("\"completed\": true"));
  EXPECT_THAT(*json, HasSubstr("\"problems\": []"));
  EXPECT_THAT(*json, ::testing::Not(HasSubstr("\"num_replans\": 0,")));
  EXPECT_TRUE(WaitForSessions(0));
  // Without a factory (the simulator tests' build) --server is refused clearly.
  absl::StatusOr<std::string> refused = SimulateCommandJson(args);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  // A server that is not there: an error, not a hang or a crash.
  std::vector<std::string> nowhere = args;
  nowhere.back() = "127.0.0.1:1";
  EXPECT_FALSE(SimulateCommandJson(nowhere, &ConnectServerPlanSource).ok());
}

}  // namespace
}  // namespace covplan
