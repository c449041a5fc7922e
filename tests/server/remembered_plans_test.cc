// In-process gRPC tests of remembered plans: repeated requests answered
// from memory under plan ids of their own, the stats-only decode of a
// served reply, hits answered while the only worker is busy, queue pricing
// of hits, and a remembered plan never answered for other map content.
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "client/remote.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/admission.h"
#include "server/covplan_server.h"
#include "server/served_replies.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/service_fixture.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::PlanRequestFor;
using ::covplan::testing::RasterMap;
using ::covplan::testing::TwoRooms;
using ::testing::HasSubstr;
using ServiceTest = ::covplan::testing::ServiceTest;

// Identical requests answered from memory share one plan's content, each
// under a plan id of its own (each call is a mission of its own): every hit
// after the first gets the first hit's reply with its own id and timings,
// and every id is resolvable by GetPlan. A request that differs (here the
// seed) is another plan.
TEST_F(ServiceTest, RepeatedHitsShareOnePlanUnderIdsOfTheirOwn) {
  const std::string map_id = PutTwoRooms();
  v1::PlanResponse cold, first;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &cold).ok());
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &first).ok());
  ASSERT_EQ(first.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  std::set<std::string> ids = {cold.plan_id(), first.plan_id()};
  for (int i = 0; i < 4; ++i) {
    v1::PlanResponse hit;
    ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &hit).ok());
    EXPECT_EQ(hit.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
    EXPECT_TRUE(ids.insert(hit.plan_id()).second) << "plan id handed out twice";
    EXPECT_TRUE(hit.stats().decomposition_cached());
    v1::PlanResponse retained;
    ASSERT_TRUE(GetPlan(hit.plan_id(), &retained).ok());
    EXPECT_EQ(retained.plan_id(), hit.plan_id());
    EXPECT_EQ(retained.path_size(), first.path_size());
    // The same plan: everything but this call's plan id and planning time.
    hit.set_plan_id(first.plan_id());
    hit.mutable_stats()->set_planning_ms(first.stats().planning_ms());
    EXPECT_EQ(hit.SerializeAsString(), first.SerializeAsString());
  }
  EXPECT_EQ(ids.size(), 6u);
  v1::PlanResponse retained;
  ASSERT_TRUE(GetPlan(first.plan_id(), &retained).ok());
  EXPECT_EQ(retained.plan_id(), first.plan_id());
  EXPECT_EQ(retained.path_size(), first.path_size());

  v1::PlanRequest other_seed = PlanRequestFor(map_id, 0.4);
  other_seed.set_seed(other_seed.seed() + 1);
  v1::PlanResponse other;
  ASSERT_TRUE(Plan(other_seed, &other).ok());
  EXPECT_NE(other.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  EXPECT_NE(other.plan_id(), first.plan_id());
}

// The load client's stats-only decode of a Plan reply gives the stats of the
// full decode, for a cold plan, a first hit and the repeated hits that are
// sent as stored bytes with this call's stats appended.
TEST_F(ServiceTest, StatsOnlyDecodeMatchesTheFullReply) {
  const std::string map_id = PutTwoRooms();
  std::unique_ptr<RemotePlanner> remote =
      RemotePlanner::Connect(absl::StrCat("127.0.0.1:", server_->port()));
  absl::StatusOr<v1::PlanStats> cold =
      remote->PlanStatsOnly(PlanRequestFor(map_id, 0.4), absl::Seconds(30));
  ASSERT_TRUE(cold.ok()) << cold.status();
  EXPECT_EQ(cold->plan_source(), v1::PLAN_SOURCE_COLD);
  EXPECT_GT(cold->num_ranks(), 0);
  for (int i = 0; i < 3; ++i) {  // the first hit, then repeated hits
    absl::StatusOr<v1::PlanResponse> full =
        remote->Plan(PlanRequestFor(map_id, 0.4), absl::Seconds(30));
    absl::StatusOr<v1::PlanStats> stats =
        remote->PlanStatsOnly(PlanRequestFor(map_id, 0.4), absl::Seconds(30));
    ASSERT_TRUE(full.ok()) << full.status();
    ASSERT_TRUE(stats.ok()) << stats.status();
    EXPECT_EQ(stats->plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
    EXPECT_TRUE(stats->decomposition_cached());
    EXPECT_GT(stats->planning_ms(), 0.0);
    v1::PlanStats expected = full->stats();
    expected.set_planning_ms(stats->planning_ms());
    EXPECT_EQ(stats->SerializeAsString(), expected.SerializeAsString()) << i;
  }
  absl::StatusOr<v1::PlanStats> missing =
      remote->PlanStatsOnly(PlanRequestFor(std::string(64, 'a'), 0.4), absl::Seconds(10));
  EXPECT_TRUE(absl::IsNotFound(missing.status())) << missing.status();
}

// A repeated hit's reply is the stored bytes and then this call's plan id
// and stats: the call's values win even when they are zero or false
// (proto3 writes no zero, so the stored copy must not hold the first
// call's values).
TEST(ServedPlanReplyTest, TheCallsStatsOverrideTheStoredReply) {
  v1::PlanResponse first;
  first.set_plan_id("p-1");
  first.add_path()->set_x(1.5);
  first.mutable_stats()->set_num_ranks(12);
  first.mutable_stats()->set_planning_ms(5.0);
  first.mutable_stats()->set_decomposition_cached(true);
  first.mutable_stats()->set_plan_source(v1::PLAN_SOURCE_CACHE_HIT);
  std::shared_ptr<const ServedBody> body = ServedBodyFor(first);
  ASSERT_NE(body, nullptr);
  for (const auto& [ms, cached] : {std::pair{0.0, false}, std::pair{0.25, true}}) {
    v1::PlanResponse call;
    call.set_plan_id("p-2");
    call.mutable_stats()->set_planning_ms(ms);
    call.mutable_stats()->set_decomposition_cached(cached);
    grpc::ByteBuffer bytes;
    ASSERT_TRUE(SerializePlanReply(call, body, &bytes).ok());
    v1::PlanResponse parsed;
    ASSERT_TRUE(parsed.ParseFromString(testing::FromBuffer(bytes)));
    v1::PlanResponse expected = first;
    expected.set_plan_id("p-2");
    expected.mutable_stats()->set_planning_ms(ms);
    expected.mutable_stats()->set_decomposition_cached(cached);
    EXPECT_EQ(parsed.SerializeAsString(), expected.SerializeAsString()) << ms;
  }
}

// Plan takes its request as bytes: bytes that are no PlanRequest are
// INVALID_ARGUMENT naming the message, and the server goes on serving.
TEST_F(ServiceTest, PlanBytesThatDoNotParseAreInvalidArgument) {
  const std::string junk("\xff\xff\xff\xff\x0f", 5);
  absl::StatusOr<std::string> reply =
      testing::RawUnaryCall(channel_, "/covplan.v1.CoveragePlanner/Plan", junk);
  EXPECT_TRUE(absl::IsInvalidArgument(reply.status())) << reply.status();
  EXPECT_THAT(reply.status().message(), HasSubstr("covplan.v1.PlanRequest"));
  v1::PlanResponse plan;
  EXPECT_TRUE(Plan(PlanRequestFor(PutTwoRooms(), 0.4), &plan).ok());
}

// The admission's expected queue wait: nothing while a worker is free, and
// the calls ahead priced by their kind.
TEST(ExpectedQueueWaitTest, PricesHitsAheadAsHits) {
  const absl::Duration solve = absl::Milliseconds(300), hit = absl::Milliseconds(1);
  EXPECT_EQ(ExpectedQueueWait(1, 0, 2, solve, hit), absl::ZeroDuration());
  EXPECT_EQ(ExpectedQueueWait(0, 0, 1, solve, hit), absl::ZeroDuration());
  // 15 searches ahead of 2 workers: 14 / 2 searches.
  EXPECT_EQ(ExpectedQueueWait(15, 0, 2, solve, hit), absl::Milliseconds(2100));
  EXPECT_EQ(ExpectedQueueWait(15, 15, 2, solve, hit), absl::Milliseconds(7));
  // 3 searches and 1 hit ahead of 2 workers: 3 calls of their mean (225.25 ms) / 2.
  EXPECT_EQ(ExpectedQueueWait(4, 1, 2, solve, hit), absl::Microseconds(337875));
  // Out-of-range counts are clamped; no worker count below 1.
  EXPECT_EQ(ExpectedQueueWait(3, 7, 0, solve, hit), absl::Milliseconds(3));
  EXPECT_EQ(ExpectedQueueWait(3, -1, 1, solve, hit), absl::Milliseconds(900));
}

// A burst of identical requests right after a cold solve and its first hit
// is answered from memory in full: the admission prices the calls ahead as
// hits, not at the cold solve's time (which refused part of such a burst).
TEST_F(ServiceTest, ABurstOfHitsAfterAColdSolveIsNotRefused) {
  const std::string map_id = PutTwoRooms();
  const absl::Time t0 = absl::Now();
  v1::PlanResponse cold, first;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &cold).ok());
  const absl::Duration cold_time = absl::Now() - t0;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &first).ok());
  ASSERT_EQ(first.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  // A deadline the cold solve's time would refuse behind a few calls.
  const absl::Duration deadline = std::max(cold_time, absl::Milliseconds(150));
  constexpr int kCalls = 16;
  std::vector<grpc::Status> statuses(kCalls);
  std::vector<std::thread> callers;
  for (int i = 0; i < kCalls; ++i) {
    callers.emplace_back([&, i] {
      grpc::ClientContext context;
      context.set_deadline(absl::ToChronoTime(absl::Now() + deadline));
      v1::PlanResponse response;
      statuses[i] = stub_->Plan(&context, PlanRequestFor(map_id, 0.4), &response);
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (const grpc::Status& status : statuses) EXPECT_TRUE(status.ok()) << status.error_message();
}

// A repeat of a hit whose reply was served before is answered on the
// network thread: while the only worker is busy and the queue holds
// nothing, searches are refused but repeated hits are still answered.
class OneWorkerServiceTest : public ServiceTest {
 protected:
  OneWorkerServiceTest() {
    worker_threads_ = 1;
    max_queue_ = 0;
    with_metrics_ = true;
    max_ranks_ = 5000;
  }
};

TEST_F(OneWorkerServiceTest, RepeatedHitsAreAnsweredWhileTheWorkerIsBusy) {
  const std::string map_id = PutTwoRooms();
  v1::PlanResponse cold, first;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &cold).ok());
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &first).ok());  // its reply is kept for the repeats
  ASSERT_EQ(first.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  v1::PutMapResponse put;
  ASSERT_TRUE(
      PutMap(RasterMap(AsciiToPgm(testing::PillarField(240, 180, 600, 5), 4), 0.025), &put).ok());
  const auto metrics = [&] {
    absl::StatusOr<std::string> body = testing::HttpGet(server_->metrics_port(), "/metrics");
    return body.ok() ? *body : std::string();
  };

  // A long search on the worker: a cold plan of 600 pillars at a 5 cm tool,
  // cancelled once the checks are done.
  grpc::ClientContext busy_context;
  busy_context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  std::thread busy([&] {
    v1::PlanRequest request = PlanRequestFor(put.map_id(), 0.05);
    request.set_time_limit_s(30);
    v1::PlanResponse response;
    stub_->Plan(&busy_context, request, &response);
  });
  bool running = false;
  for (int i = 0; i < 1000 && !running; ++i) {
    running = absl::StrContains(metrics(), "\ncovplan_solves_in_flight 1\n");
    if (!running) absl::SleepFor(absl::Milliseconds(10));
  }
  // A search is refused: the worker is busy and the queue holds none.
  const auto refused = [&] {
    v1::PlanResponse response;
    return Plan(PlanRequestFor(map_id, 0.3), &response).error_code() ==
           grpc::StatusCode::RESOURCE_EXHAUSTED;
  };
  const bool refused_before = running && refused();
  constexpr int kRepeats = 20;
  std::vector<grpc::Status> statuses(kRepeats);
  std::vector<v1::PlanResponse> repeats(kRepeats);
  for (int i = 0; i < kRepeats && refused_before; ++i) {
    statuses[i] = Plan(PlanRequestFor(map_id, 0.4), &repeats[i]);
  }
  const bool refused_after = refused_before && refused();
  busy_context.TryCancel();
  busy.join();

  ASSERT_TRUE(running) << "the long search never started";
  ASSERT_TRUE(refused_before) << "a search was admitted beside the long one";
  EXPECT_TRUE(refused_after) << "the long search ended before the repeats were checked";
  for (int i = 0; i < kRepeats; ++i) {
    ASSERT_TRUE(statuses[i].ok()) << statuses[i].error_message();
    const v1::PlanResponse& again = repeats[i];
    EXPECT_EQ(again.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
    EXPECT_NE(again.plan_id(), first.plan_id());
    for (int j = 0; j < i; ++j) EXPECT_NE(again.plan_id(), repeats[j].plan_id());
    EXPECT_TRUE(again.stats().decomposition_cached());
    ASSERT_EQ(again.path_size(), first.path_size());
    for (int k = 0; k < again.path_size(); ++k) {
      EXPECT_EQ(again.path(k).x(), first.path(k).x());
      EXPECT_EQ(again.path(k).y(), first.path(k).y());
    }
  }
  EXPECT_THAT(metrics(),
              HasSubstr(absl::StrCat("\ncovplan_plan_hits_without_worker_total ", kRepeats, "\n")));
}

// Remembered plans follow map content: the id is the content's, DeleteMap
// forgets the plans with the artifacts, and other content is another id.
TEST_F(ServiceTest, RememberedPlansAreNeverAnsweredForOtherMapContent) {
  const std::string map_id = PutTwoRooms();
  v1::PlanResponse cold, hit;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &cold).ok());
  EXPECT_EQ(cold.stats().plan_source(), v1::PLAN_SOURCE_COLD);
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &hit).ok());
  EXPECT_EQ(hit.stats().plan_source(), v1::PLAN_SOURCE_CACHE_HIT);
  ASSERT_EQ(hit.path_size(), cold.path_size());
  for (int i = 0; i < cold.path_size(); ++i) {
    EXPECT_EQ(hit.path(i).x(), cold.path(i).x());
    EXPECT_EQ(hit.path(i).y(), cold.path(i).y());
  }
  EXPECT_NE(hit.plan_id(), cold.plan_id());

  // Deleted, then stored again under the same (content) id: planned afresh.
  {
    grpc::ClientContext context;
    v1::DeleteMapRequest del;
    del.set_map_id(map_id);
    v1::DeleteMapResponse deleted;
    ASSERT_TRUE(stub_->DeleteMap(&context, del, &deleted).ok());
  }
  v1::PlanResponse gone;
  EXPECT_EQ(Plan(PlanRequestFor(map_id, 0.4), &gone).error_code(), grpc::StatusCode::NOT_FOUND);
  ASSERT_EQ(PutTwoRooms(), map_id);
  v1::PlanResponse fresh;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &fresh).ok());
  EXPECT_EQ(fresh.stats().plan_source(), v1::PLAN_SOURCE_COLD);

  // Other content (a wall opened): another id, never the old plan.
  std::vector<std::string> rows = testing::TwoRooms();
  rows[2][5] = '.';
  v1::PutMapResponse put;
  ASSERT_TRUE(PutMap(RasterMap(AsciiToPgm(rows, 4), 0.1), &put).ok());
  ASSERT_NE(put.map_id(), map_id);
  v1::PlanResponse other;
  ASSERT_TRUE(Plan(PlanRequestFor(put.map_id(), 0.4), &other).ok());
  EXPECT_EQ(other.stats().plan_source(), v1::PLAN_SOURCE_COLD);
  EXPECT_EQ(other.stats().free_cells(), cold.stats().free_cells() + 1);

  // Bad input is still refused, remembered plan or not.
  v1::PlanRequest bad = PlanRequestFor(map_id, 0.4);
  bad.set_time_limit_s(-1);
  v1::PlanResponse refused;
  EXPECT_EQ(Plan(bad, &refused).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

}  // namespace
}  // namespace covplan
