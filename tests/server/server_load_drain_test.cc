// Integration tests of load-handling defects against a real
// covplan-server process: malformed protobuf logged and counted, time lost
// in the queue answered as overload, PutMaps past their deadline dropped
// unstarted while reads go on, a drain that keeps its grace and answers
// running plans with their best tour.
#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "png.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/hardening_fixture.h"
#include "tests/server/server_process.h"
#include "tests/testing/png_writer.h"
#include "tests/testing/test_maps.h"
#include "tests/testing/timing.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::HealthWatch;
using ::covplan::testing::kNotServing;
using ::covplan::testing::kServing;
using ::covplan::testing::PillarField;
using ::covplan::testing::RasterMap;
using ::covplan::testing::ServerHardeningTest;
using ::covplan::testing::ServerProcess;
using ::covplan::testing::SetDirReadOnly;
using ::testing::HasSubstr;
using ::testing::Not;

// Defect 13: a request that is not its protobuf.
TEST_F(ServerHardeningTest, MalformedRequestsAreInvalidArgumentLoggedAndCounted) {
  StartServer({"--metrics_port=0"});
  absl::StatusOr<std::string> reply = testing::RawUnaryCall(
      channel_, "/covplan.v1.CoveragePlanner/PutMap", std::string("\xff\xff\xff\xff\x0f", 5));
  EXPECT_TRUE(absl::IsInvalidArgument(reply.status())) << reply.status();
  EXPECT_THAT(reply.status().message(), HasSubstr("covplan.v1.PutMapRequest"));
  EXPECT_THAT(server_->log(), HasSubstr("method=PutMap code=INVALID_ARGUMENT"));
  absl::StatusOr<std::string> metrics = testing::HttpGet(server_->metrics_port(), "/metrics");
  ASSERT_TRUE(metrics.ok()) << metrics.status();
  EXPECT_THAT(*metrics,
              HasSubstr("covplan_requests_total{code=\"INVALID_ARGUMENT\",method=\"PutMap\"} 1"));
}

// Defect 9: a call admitted behind a long solve that starts with too little
// of its deadline left is refused as overload, not DEADLINE_EXCEEDED.
TEST_F(ServerHardeningTest, TimeLostInTheQueueIsResourceExhaustedNotDeadlineExceeded) {
  // The all-pairs transitions and the dense GTSP (not the much faster sparse
  // path) keep the busy solve long enough.
  StartServer({"--threads=1", "--dense_transition_mb=1024"});
  const std::string busy_map =
      PutMapOk(RasterMap(AsciiToPgm(PillarField(120, 90, 200, 3), 4), 0.05));
  const std::string fresh_map =
      PutMapOk(RasterMap(AsciiToPgm(PillarField(240, 180, 600, 5), 4), 0.025));
  v1::PlanResponse warm;
  ASSERT_TRUE(Plan(busy_map, 0.3, &warm).ok());
  std::thread busy([&] {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::PlanRequest request = testing::PlanRequestFor(busy_map, 0.3);
    request.set_time_limit_s(2.0);
    v1::PlanResponse response;
    EXPECT_TRUE(stub_->Plan(&context, request, &response).ok());
  });
  absl::SleepFor(absl::Milliseconds(100));
  // Waits ~1.9 s for the worker, then has ~0.6 s (under sanitizers, which
  // slow the busy solve's overrun and the reply, ~2 s) for a map whose
  // artifacts take longer than that to build.
  grpc::ClientContext context;
  context.set_deadline(
      std::chrono::system_clock::now() +
      std::chrono::milliseconds(2000 + static_cast<int64_t>(500 * testing::kTimingSlowdown)));
  v1::PlanRequest request = testing::PlanRequestFor(fresh_map, 0.2);
  v1::PlanResponse response;
  const grpc::Status status = stub_->Plan(&context, request, &response);
  busy.join();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
      << status.error_message() << server_->log();
  EXPECT_THAT(status.error_message(), HasSubstr("server busy"));
}

// Defect 2: PutMaps whose deadline passed while they waited are not
// decoded, and GetMap does not wait behind decoding.
TEST_F(ServerHardeningTest, QueuedPutMapsPastTheirDeadlineAreDroppedAndReadsDoNotWait) {
  StartServer();
  testing::PngSpec spec;
  spec.width = 3000;
  spec.height = 3000;
  spec.color_type = PNG_COLOR_TYPE_GRAY;
  spec.bit_depth = 16;
  spec.samples.assign(static_cast<size_t>(spec.width) * spec.height, 65535);
  const v1::Map big = RasterMap(testing::EncodePng(spec), 0.05);
  const std::string small_id = PutMapOk(Variant(0));
  const absl::Time one_start = absl::Now();
  PutMapOk(big);
  const absl::Duration one = absl::Now() - one_start;  // one decode, uncontended
  // Enough PutMaps that decoding them all would take >= 4 s on the 2 I/O
  // threads; each may wait 0.5 s.
  const int n = std::clamp(
      static_cast<int>(8 * absl::Seconds(1) / std::max(one, absl::Milliseconds(10))), 8, 60);
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<v1::PutMapRequest> requests(n);
  std::vector<v1::PutMapResponse> responses(n);
  std::atomic<int> done{0};
  const absl::Time fired = absl::Now();
  for (int i = 0; i < n; ++i) {
    contexts.push_back(std::make_unique<grpc::ClientContext>());
    contexts.back()->set_deadline(absl::ToChronoTime(fired + absl::Milliseconds(500)));
    *requests[i].mutable_map() = big;
    stub_->async()->PutMap(contexts.back().get(), &requests[i], &responses[i],
                           [&done](grpc::Status) { done.fetch_add(1); });
  }
  absl::SleepFor(absl::Milliseconds(100));
  const absl::Time read_start = absl::Now();
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(300));
    v1::GetMapRequest request;
    request.set_map_id(small_id);
    v1::GetMapResponse response;
    const grpc::Status status = stub_->GetMap(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
  EXPECT_LT(absl::Now() - read_start, absl::Milliseconds(300));
  while (done.load() < n && absl::Now() < fired + absl::Seconds(60))
    absl::SleepFor(absl::Milliseconds(10));
  ASSERT_EQ(done.load(), n);
  // The server stops working on them soon after their deadline: a small
  // PutMap right after is answered at once, not behind the queue.
  const absl::Time after = absl::Now();
  EXPECT_FALSE(PutMapOk(Variant(1)).empty());
  EXPECT_LT(absl::Now() - after, 2 * one + absl::Milliseconds(300))
      << "one decode takes " << absl::FormatDuration(one) << ", " << n << " PutMaps";
  EXPECT_THAT(server_->log(), HasSubstr("not started"));
}

// Defect 7: an open Watch stream, an idle connection and a plan longer than
// the grace; the process still exits within the grace plus a small bound,
// and the plan is answered with its best tour, marked cut short by the drain.
TEST_F(ServerHardeningTest, DrainKeepsItsGraceAndAnswersWithTheBestPlan) {
  // Without remembered plans: the seed-2 request must search, not warm-start.
  // The dense GTSP keeps searching for its whole budget (the sparse path
  // converges before the drain).
  StartServer(
      {"--drain_grace_s=1", "--threads=1", "--plan_memory=false", "--dense_transition_mb=1024"});
  const std::string map_id = PutMapOk(RasterMap(AsciiToPgm(PillarField(120, 90, 200, 3), 4), 0.05));
  v1::PlanResponse warm;
  ASSERT_TRUE(
      Plan(map_id, 0.3, &warm).ok());  // artifacts cached: the next search has a plan at once
  ASSERT_GT(warm.stats().num_ranks(), 100);
  HealthWatch watch(channel_);
  v1::PlanResponse long_plan;
  grpc::Status long_status;
  std::thread planner([&] {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    v1::PlanRequest request = testing::PlanRequestFor(map_id, 0.3);
    request.set_time_limit_s(30);
    request.set_seed(2);
    long_status = stub_->Plan(&context, request, &long_plan);
  });
  absl::SleepFor(absl::Milliseconds(500));
  const absl::Time term = absl::Now();
  server_->Terminate();
  const int exit_status = server_->Wait(absl::Seconds(20));
  const absl::Duration took = absl::Now() - term;
  planner.join();
  EXPECT_EQ(exit_status, 0);
  RecordProperty("drain_ms", static_cast<int>(absl::ToInt64Milliseconds(took)));
  std::cout << "SIGTERM to exit: " << absl::FormatDuration(took) << " (grace 1 s)\n";
  EXPECT_LT(took, absl::Milliseconds(1000 + 1000)) << server_->log();
  EXPECT_THAT(server_->log(), Not(HasSubstr("drain overran")));
  ASSERT_TRUE(long_status.ok()) << long_status.error_message();
  EXPECT_TRUE(long_plan.stats().tour_cut_short());
  EXPECT_THAT(long_plan.termination().detail(), HasSubstr("drain"));
  EXPECT_FALSE(long_plan.path().empty());
  EXPECT_TRUE(watch.WaitDone(absl::Seconds(5)));
  EXPECT_GE(watch.reads(), 1);
}

}  // namespace
}  // namespace covplan
