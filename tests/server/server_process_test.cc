// Integration tests against a real covplan-server process on loopback:
// maps survive a restart, a corrupted map file is reported, a 150 ms deadline
// is met with a valid (cut short) plan, a cancelled call frees its worker,
// overload is refused with RESOURCE_EXHAUSTED and the server recovers, bad
// input is INVALID_ARGUMENT over the wire, metrics families are exposed,
// SIGTERM drains in-flight work.
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/server_process.h"
#include "tests/testing/test_maps.h"
#include "tests/testing/timing.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::PillarField;
using ::covplan::testing::RasterMap;
using ::covplan::testing::ServerProcess;
using ::covplan::testing::TwoRooms;
using ::testing::Contains;
using ::testing::HasSubstr;

// The furnished office at a 0.5 m tool: about 100 ranks, whose full GTSP
// search takes a few hundred milliseconds on this machine.
v1::Map OfficeMap() {
  absl::StatusOr<v1::Map> map =
      MapProtoFromFile(absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office_furnished.yaml"),
                       MapFileOverrides(), EngineLimits());
  EXPECT_TRUE(map.ok()) << map.status();
  return map.ok() ? *map : v1::Map();
}

class ServerProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "covplan_process_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    store_ = root_ + "/maps";
  }
  void TearDown() override {
    server_.reset();
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }

  // testing::QuietServerFlags, then `args` (the last flag wins).
  void StartServer(const std::vector<std::string>& args = {}) {
    server_ = std::make_unique<ServerProcess>();
    std::vector<std::string> all = testing::QuietServerFlags();
    all.insert(all.end(), args.begin(), args.end());
    const absl::Status started = server_->Start(store_, all);
    ASSERT_TRUE(started.ok()) << started;
    channel_ = grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials());
    stub_ = v1::CoveragePlanner::NewStub(channel_);
  }

  // Closes our connection first: gRPC's graceful shutdown otherwise waits
  // seconds for the idle client's GOAWAY round trip.
  int StopServer() {
    stub_.reset();
    channel_.reset();
    return server_->Stop();
  }

  std::string PutMap(const v1::Map& map) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::PutMapRequest request;
    *request.mutable_map() = map;
    v1::PutMapResponse response;
    const grpc::Status status = stub_->PutMap(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.map_id();
  }

  grpc::Status Plan(const v1::PlanRequest& request, v1::PlanResponse* response,
                    std::optional<absl::Duration> deadline = absl::Seconds(30)) {
    grpc::ClientContext context;
    if (deadline) context.set_deadline(absl::ToChronoTime(absl::Now() + *deadline));
    return stub_->Plan(&context, request, response);
  }

  static v1::PlanRequest Request(const std::string& map_id, double tool, double time_limit_s) {
    v1::PlanRequest request;
    request.set_map_id(map_id);
    request.mutable_robot()->set_tool_width_m(tool);
    request.set_time_limit_s(time_limit_s);
    return request;
  }

  std::string root_;
  std::string store_;
  std::unique_ptr<ServerProcess> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(ServerProcessTest, MapsSurviveARestart) {
  StartServer();
  const std::string map_id = PutMap(RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1));
  ASSERT_EQ(StopServer(), 0) << server_->log();

  StartServer();
  grpc::ClientContext context;
  v1::ListMapsResponse list;
  ASSERT_TRUE(stub_->ListMaps(&context, v1::ListMapsRequest(), &list).ok());
  ASSERT_EQ(list.maps_size(), 1);
  EXPECT_EQ(list.maps(0).map_id(), map_id);
  EXPECT_EQ(list.corrupted_size(), 0);
  v1::PlanResponse plan;
  const grpc::Status status = Plan(Request(map_id, 0.4, 0.5), &plan);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(plan.ranks_size(), 0);
}

// A server killed with SIGKILL mid-mission: after the restart the robot goes
// on replanning with the plan_id it holds, twice over (the replanned plan is
// persisted too), and resumes from the progress it reported before a third kill.
TEST_F(ServerProcessTest, AMissionSurvivesSigkill) {
  StartServer();
  const std::string map_id = PutMap(OfficeMap());
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(Request(map_id, 0.8, 0.5), &plan).ok());
  std::string trace = absl::StrFormat("start (%.3f, %.3f)", plan.path(0).x(),
                                      plan.path(0).y());  // for a failure's message
  auto replan = [&](const v1::PlanResponse& p, v1::ReplanResponse* out) {
    v1::ReplanRequest r;
    r.set_plan_id(p.plan_id());
    const int k = p.path_size() / 5;
    r.mutable_progress()->set_waypoint(k);
    r.mutable_progress()->mutable_position()->set_x(p.path(k - 1).x());
    r.mutable_progress()->mutable_position()->set_y(p.path(k - 1).y());
    // The obstacle lies on the path ahead.
    const int j = std::min(k + 3, p.path_size() - 1);
    v1::Point2* obstacle = r.mutable_obstacles()->add_points();
    obstacle->set_x(p.path(j).x());
    obstacle->set_y(p.path(j).y());
    absl::StrAppendFormat(&trace, "; obstacle at (%.3f, %.3f), waypoint %d of %d", p.path(j).x(),
                          p.path(j).y(), j, p.path_size());
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->Replan(&context, r, out);
  };
  // Plans are written to the store right after the reply (off its path).
  auto stored = [&](const std::string& id) {
    for (int i = 0; i < 250 && !std::filesystem::exists(store_ + "/plans/" + id + ".plan"); ++i) {
      absl::SleepFor(absl::Milliseconds(20));
    }
    return std::filesystem::exists(store_ + "/plans/" + id + ".plan");
  };
  ASSERT_TRUE(stored(plan.plan_id()));
  ASSERT_EQ(::kill(server_->pid(), SIGKILL), 0);
  EXPECT_EQ(server_->Wait(absl::Seconds(10)), 128 + SIGKILL);
  stub_.reset();
  channel_.reset();
  StartServer();
  v1::ReplanResponse first;
  grpc::Status status = replan(plan, &first);
  ASSERT_TRUE(status.ok()) << status.error_message() << "\n" << server_->log();
  EXPECT_GT(first.replan().remaining_cells(), 0);
  ASSERT_TRUE(stored(first.plan().plan_id()));
  ASSERT_EQ(::kill(server_->pid(), SIGKILL), 0);
  EXPECT_EQ(server_->Wait(absl::Seconds(10)), 128 + SIGKILL);
  stub_.reset();
  channel_.reset();
  StartServer();
  v1::ReplanResponse second;
  status = replan(first.plan(), &second);
  ASSERT_TRUE(status.ok()) << status.error_message() << "\n" << server_->log();
  EXPECT_LE(second.replan().remaining_cells(), first.replan().remaining_cells());
  std::set<int> swept;
  for (const v1::CoverageSweep& s : second.plan().sweeps())
    swept.insert(s.cells().begin(), s.cells().end());
  EXPECT_EQ(static_cast<int>(swept.size()), second.replan().remaining_cells());

  // The robot reports its progress in a Drive session, is interrupted with
  // the server (SIGKILL again), and resumes where it stopped from where that
  // plan started. (Not from the first dock: an obstacle reported in a
  // doorway may cut the dock's room off from the rest, and Resume then
  // rightly refuses it; which doorway depends on the tour its deadline cut.)
  const v1::PlanResponse& driving = second.plan();
  const int k = driving.path_size() / 2;
  {
    grpc::ClientContext context;
    auto stream = stub_->Drive(&context);
    v1::DriveRequest first;
    first.set_plan_id(driving.plan_id());
    ASSERT_TRUE(stream->Write(first));
    v1::DriveEvent ready;
    ASSERT_TRUE(stream->Read(&ready));
    v1::DriveRequest report;
    report.mutable_progress()->set_waypoint(k);
    report.mutable_progress()->mutable_position()->set_x(driving.path(k - 1).x());
    report.mutable_progress()->mutable_position()->set_y(driving.path(k - 1).y());
    ASSERT_TRUE(stream->Write(report));
    stream->WritesDone();
    ASSERT_TRUE(stream->Finish().ok());
  }
  const std::string progress_file = store_ + "/plans/" + driving.plan_id() + ".progress";
  for (int i = 0; i < 250 && !std::filesystem::exists(progress_file); ++i)
    absl::SleepFor(absl::Milliseconds(20));
  ASSERT_TRUE(std::filesystem::exists(progress_file));
  ASSERT_EQ(::kill(server_->pid(), SIGKILL), 0);
  EXPECT_EQ(server_->Wait(absl::Seconds(10)), 128 + SIGKILL);
  stub_.reset();
  channel_.reset();
  StartServer();
  v1::ResumeRequest resume;
  resume.set_plan_id(driving.plan_id());
  const v1::Waypoint& from = driving.path(0);
  resume.mutable_pose()->set_x(from.x());
  resume.mutable_pose()->set_y(from.y());
  absl::StrAppendFormat(&trace, "; resumed from (%.3f, %.3f)", from.x(), from.y());
  v1::ReplanResponse resumed;
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    status = stub_->Resume(&context, resume, &resumed);
  }
  ASSERT_TRUE(status.ok()) << status.error_message() << "\n" << trace << "\n" << server_->log();
  EXPECT_EQ(resumed.replan().progress_source(), "recorded");
  EXPECT_GT(resumed.replan().covered_cells_before(), 0);
  EXPECT_EQ(resumed.replan().covered_cells_before() + resumed.replan().remaining_cells(),
            second.replan().remaining_cells());
  EXPECT_NEAR(resumed.plan().path(0).x(), from.x(), 1e-9);
  EXPECT_NEAR(resumed.plan().path(0).y(), from.y(), 1e-9);
}

TEST_F(ServerProcessTest, CorruptedMapFileIsReportedNotServed) {
  StartServer();
  const std::string map_id = PutMap(RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1));
  ASSERT_EQ(StopServer(), 0);
  {
    std::fstream f(store_ + "/" + map_id + ".map", std::ios::in | std::ios::out | std::ios::binary);
    ASSERT_TRUE(f.good());
    f.seekp(-20, std::ios::end);
    f.put('\x01');
  }
  StartServer();
  EXPECT_THAT(server_->log(), HasSubstr("corrupted map file"));
  {
    grpc::ClientContext context;
    v1::ListMapsResponse list;
    ASSERT_TRUE(stub_->ListMaps(&context, v1::ListMapsRequest(), &list).ok());
    EXPECT_EQ(list.maps_size(), 0);
    EXPECT_THAT(list.corrupted(), Contains(map_id));
  }
  v1::PlanResponse plan;
  grpc::Status status = Plan(Request(map_id, 0.4, 0.5), &plan);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DATA_LOSS);
  EXPECT_THAT(status.error_message(), HasSubstr("corrupted"));
  grpc::ClientContext context;
  v1::GetMapRequest get;
  get.set_map_id(map_id);
  v1::GetMapResponse got;
  EXPECT_EQ(stub_->GetMap(&context, get, &got).error_code(), grpc::StatusCode::DATA_LOSS);
  // PutMap again repairs it.
  EXPECT_EQ(PutMap(RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1)), map_id);
  EXPECT_TRUE(Plan(Request(map_id, 0.4, 0.5), &plan).ok());
}

// The short deadline: sanitizers slow the server down, so the same property
// is checked there at a proportionally longer deadline
// (testing::kTimingSlowdown).
constexpr absl::Duration kShortDeadline =
    absl::Milliseconds(static_cast<int64_t>(150 * testing::kTimingSlowdown));

TEST_F(ServerProcessTest, ShortDeadlineGetsAValidPlanInTime) {
  // The repeated request must search under its deadline, not be remembered.
  StartServer({"--plan_memory=false"});
  const std::string map_id = PutMap(OfficeMap());
  // Warm the decomposition cache; the full search gets a generous budget.
  v1::PlanResponse full;
  const absl::Time start_full = absl::Now();
  ASSERT_TRUE(Plan(Request(map_id, 0.5, 10.0), &full).ok());
  const absl::Duration full_time = absl::Now() - start_full;
  ASSERT_GT(full.ranks_size(), 50);

  int cut_short = 0;
  for (int i = 0; i < 3; ++i) {
    v1::PlanResponse plan;
    const absl::Time start = absl::Now();
    const grpc::Status status = Plan(Request(map_id, 0.5, 10.0), &plan, kShortDeadline);
    const absl::Duration took = absl::Now() - start;
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_LT(took, kShortDeadline);
    EXPECT_TRUE(plan.stats().decomposition_cached());
    EXPECT_EQ(plan.stats().plan_source(), v1::PLAN_SOURCE_COLD);  // --plan_memory=false
    // A valid plan: every rank visited once.
    EXPECT_EQ(plan.rank_order_size(), plan.ranks_size());
    std::vector<int> order(plan.rank_order().begin(), plan.rank_order().end());
    std::sort(order.begin(), order.end());
    for (int r = 0; r < static_cast<int>(order.size()); ++r) EXPECT_EQ(order[r], r);
    cut_short += plan.stats().tour_cut_short();
  }
  // Whenever the uncut search needs longer than the deadline, the reply says so.
  if (full_time > kShortDeadline + absl::Milliseconds(50)) {
    EXPECT_EQ(cut_short, 3);
  }
}

TEST_F(ServerProcessTest, DeadlineTooShortForAFirstPlanIsDeadlineExceeded) {
  StartServer({"--deadline_margin_ms=25"});
  const std::string map_id = PutMap(OfficeMap());
  v1::PlanResponse plan;
  const absl::Time start = absl::Now();
  // Uncached decomposition and a 20 ms deadline: below the reply margin.
  const grpc::Status status = Plan(Request(map_id, 0.5, 10.0), &plan, absl::Milliseconds(20));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_LT(absl::Now() - start, absl::Milliseconds(500));
}

TEST_F(ServerProcessTest, CancelledCallFreesItsWorker) {
  // 120 x 100 cells of 0.5 m with 300 pillars: seconds of all-pairs
  // transition paths and dense tour search (the sparse path would finish
  // before the cancel).
  StartServer({"--threads=1", "--max_queue=0", "--dense_transition_mb=1024"});
  const std::string big = PutMap(RasterMap(AsciiToPgm(PillarField(120, 100, 300, 5), 5), 0.1));
  const std::string small = PutMap(RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1));

  // A long request (60 s budget, no deadline) occupies the only worker...
  grpc::ClientContext long_context;
  grpc::Status long_status;
  std::thread long_call([&] {
    v1::PlanResponse response;
    long_status = stub_->Plan(&long_context, Request(big, 0.5, 60.0), &response);
  });
  absl::SleepFor(absl::Milliseconds(300));
  {
    v1::PlanResponse busy;
    const grpc::Status status = Plan(Request(small, 0.4, 0.1), &busy);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  }
  // ...until the client cancels it.
  long_context.TryCancel();
  long_call.join();
  EXPECT_EQ(long_status.error_code(), grpc::StatusCode::CANCELLED);
  grpc::Status status;
  const absl::Time cancelled_at = absl::Now();
  for (int i = 0; i < 100; ++i) {  // the worker notices within its poll interval
    v1::PlanResponse plan;
    status = Plan(Request(small, 0.4, 0.1), &plan);
    if (status.ok()) break;
    absl::SleepFor(absl::Milliseconds(20));
  }
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_LT(absl::Now() - cancelled_at, absl::Seconds(2));
  EXPECT_THAT(server_->log(), HasSubstr("code=CANCELLED"));
}

TEST_F(ServerProcessTest, OverloadIsRefusedQuicklyAndRecovers) {
  // Identical requests must each search, not be answered from memory: with
  // plan memory on, a warm-up search that converged answers every later call
  // at once and nothing is ever refused.
  StartServer({"--threads=1", "--max_queue=1", "--plan_memory=false"});
  const std::string map_id = PutMap(OfficeMap());
  v1::PlanResponse warm;
  ASSERT_TRUE(Plan(Request(map_id, 0.5, 0.2), &warm).ok());

  constexpr int kCalls = 6;
  std::vector<grpc::StatusCode> codes(kCalls);
  std::vector<absl::Duration> latency(kCalls);
  std::vector<std::thread> threads;
  for (int i = 0; i < kCalls; ++i) {
    threads.emplace_back([&, i] {
      v1::PlanResponse response;
      const absl::Time start = absl::Now();
      codes[i] = Plan(Request(map_id, 0.5, 1.0), &response).error_code();
      latency[i] = absl::Now() - start;
    });
  }
  for (std::thread& t : threads) t.join();
  int ok = 0, refused = 0;
  for (int i = 0; i < kCalls; ++i) {
    if (codes[i] == grpc::StatusCode::OK) ++ok;
    if (codes[i] == grpc::StatusCode::RESOURCE_EXHAUSTED) {
      ++refused;
      EXPECT_LT(latency[i], absl::Milliseconds(250));  // refused at once, not queued
    }
  }
  EXPECT_EQ(ok + refused, kCalls);
  EXPECT_GE(ok, 1);
  EXPECT_GE(refused, kCalls - 2 - 1);  // at most 1 running + 1 queued (+1 scheduling slack)
  v1::PlanResponse after;
  EXPECT_TRUE(Plan(Request(map_id, 0.5, 0.2), &after).ok());
}

TEST_F(ServerProcessTest, QueueWaitBeyondTheDeadlineIsRefusedAtOnce) {
  // Identical requests must each search for ~1 s, not be answered from memory.
  StartServer({"--threads=1", "--max_queue=4", "--plan_memory=false"});
  const std::string map_id = PutMap(OfficeMap());
  // Warm the cache and teach the server that a solve takes ~1 s.
  v1::PlanResponse warm;
  ASSERT_TRUE(Plan(Request(map_id, 0.5, 1.0), &warm).ok());
  ASSERT_TRUE(Plan(Request(map_id, 0.5, 1.0), &warm).ok());
  // Two 1 s solves hold the worker and the queue...
  std::vector<std::thread> busy;
  for (int i = 0; i < 2; ++i) {
    busy.emplace_back([&] {
      v1::PlanResponse response;
      EXPECT_TRUE(Plan(Request(map_id, 0.5, 1.0), &response).ok());
    });
  }
  absl::SleepFor(absl::Milliseconds(150));
  // ...so a call with a 300 ms deadline would only wait and expire: it is
  // refused at once instead of answering DEADLINE_EXCEEDED later.
  v1::PlanResponse response;
  const absl::Time start = absl::Now();
  const grpc::Status status = Plan(Request(map_id, 0.5, 1.0), &response, absl::Milliseconds(300));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("queue wait"));
  EXPECT_LT(absl::Now() - start, absl::Milliseconds(200));
  for (std::thread& t : busy) t.join();
}

TEST_F(ServerProcessTest, BadInputIsInvalidArgumentOverTheWire) {
  StartServer();
  const std::string pgm = AsciiToPgm(TwoRooms(), 4);
  struct Case {
    v1::PlanRequest request;
    std::string message;
  };
  std::vector<Case> cases;
  auto inline_request = [&](const v1::Map& map, double tool) {
    v1::PlanRequest r;
    *r.mutable_map() = map;
    r.mutable_robot()->set_tool_width_m(tool);
    return r;
  };
  cases.push_back({inline_request(RasterMap(pgm, 0.1), 0), "tool_width_m"});
  cases.push_back({inline_request(RasterMap(pgm, -0.1), 0.4), "resolution"});
  cases.push_back({inline_request(RasterMap(pgm, 0.1), 0.05), "narrower than one map pixel"});
  cases.push_back({inline_request(RasterMap(pgm, 0.1), 50), "wider than the map"});
  cases.push_back({inline_request(RasterMap(pgm.substr(0, 50), 0.1), 0.4), "map.raster.image"});
  cases.push_back({inline_request(RasterMap(AsciiToPgm({"###", "###"}, 4), 0.1), 0.4), "no free"});
  for (const Case& c : cases) {
    v1::PlanResponse response;
    const grpc::Status status = Plan(c.request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.message;
    EXPECT_THAT(status.error_message(), HasSubstr(c.message));
  }
}

TEST_F(ServerProcessTest, MetricsHealthAndDrainOnSigterm) {
  StartServer({"--metrics_port=0", "--drain_grace_s=10", "--drain_notice_s=1"});
  const std::string map_id = PutMap(OfficeMap());
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(Request(map_id, 0.5, 0.2), &plan).ok());
  absl::StatusOr<std::string> metrics = testing::HttpGet(server_->metrics_port(), "/metrics");
  ASSERT_TRUE(metrics.ok()) << metrics.status();
  for (const char* family :
       {"covplan_requests_total", "covplan_request_duration_seconds_bucket",
        "covplan_plan_solve_duration_seconds", "covplan_worker_queue_depth",
        "covplan_solves_in_flight", "covplan_artifact_cache_hits_total",
        "covplan_artifact_cache_misses_total", "covplan_artifact_cache_evictions_total",
        "covplan_artifact_cache_bytes", "covplan_plans_cut_short_total"}) {
    EXPECT_THAT(*metrics, HasSubstr(family));
  }
  absl::StatusOr<int> health = testing::HealthStatus(channel_, "");
  ASSERT_TRUE(health.ok());
  EXPECT_EQ(*health, 1);

  // An in-flight call completes although SIGTERM arrives meanwhile.
  grpc::Status in_flight;
  std::thread call([&] {
    v1::PlanResponse response;
    in_flight = Plan(Request(map_id, 0.5, 1.0), &response);
  });
  absl::SleepFor(absl::Milliseconds(200));
  server_->Terminate();
  absl::SleepFor(absl::Milliseconds(300));  // within the drain notice
  health = testing::HealthStatus(channel_, "");
  ASSERT_TRUE(health.ok()) << health.status();
  EXPECT_EQ(*health, 2);  // NOT_SERVING
  {
    v1::PlanResponse refused;
    EXPECT_EQ(Plan(Request(map_id, 0.5, 0.2), &refused).error_code(),
              grpc::StatusCode::UNAVAILABLE);
  }
  call.join();
  EXPECT_TRUE(in_flight.ok()) << in_flight.error_message();
  EXPECT_EQ(server_->Wait(absl::Seconds(15)), 0) << server_->log();
  EXPECT_THAT(server_->log(), HasSubstr("msg=\"draining\""));
  EXPECT_THAT(server_->log(), HasSubstr("req="));  // request ids in the logs
}

}  // namespace
}  // namespace covplan
