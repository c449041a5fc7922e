// The live events of a map (server/live_events.h) and their stream on the
// JSON API (GET /v1/events?map_id=...): the hub delivers a map's events to
// that map's subscribers only, bounds subscribers and queues, and wakes them
// on Close. Over HTTP, a watcher of a map sees a Drive session on it open,
// report progress and obstacles, get its new plan (which method, how long)
// and end, in that order, as the robot's own stream saw them; a caller who
// may not read the map gets gRPC's answer (404 for another tenant's map,
// 401 without a token), and bad requests a clear error.
#include "server/live_events.h"

#include <google/protobuf/util/json_util.h>
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "api/digest.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/grpc_probe.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::HttpReply;
using ::covplan::testing::HttpRequest;
using ::covplan::testing::HttpStream;
using ::covplan::testing::PlanRequestFor;
using ::covplan::testing::RasterMap;
using ::covplan::testing::TwoRooms;

v1::LiveEvent Progress(const std::string& map_id, int waypoint) {
  v1::LiveEvent e;
  e.set_map_id(map_id);
  e.mutable_progress()->set_waypoint(waypoint);
  return e;
}

TEST(LiveEventsHub, DeliversAMapsEventsToItsSubscribersOnly) {
  LiveEvents hub(/*max_subscribers=*/3, /*queue_limit=*/4);
  std::shared_ptr<LiveEvents::Subscription> a = hub.Subscribe("map-a");
  std::shared_ptr<LiveEvents::Subscription> a2 = hub.Subscribe("map-a");
  std::shared_ptr<LiveEvents::Subscription> b = hub.Subscribe("map-b");
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(hub.Subscribe("map-c"), nullptr) << "a fourth subscriber beyond the bound";
  EXPECT_TRUE(hub.Watched("map-a"));
  EXPECT_FALSE(hub.Watched("map-c"));
  hub.Publish(Progress("map-a", 1));
  hub.Publish(Progress("map-c", 2));  // nobody watches: dropped silently
  LiveEvents::Batch got = a->Next(absl::Seconds(5));
  ASSERT_EQ(got.events.size(), 1u);
  v1::LiveEvent e;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(got.events[0], &e).ok());
  EXPECT_EQ(e.map_id(), "map-a");
  EXPECT_EQ(e.progress().waypoint(), 1);
  EXPECT_EQ(a2->Next(absl::Seconds(5)).events.size(), 1u);
  EXPECT_TRUE(b->Next(absl::Milliseconds(20)).events.empty());
  // A slow subscriber loses its oldest events, and is told how many.
  for (int k = 1; k <= 6; ++k) hub.Publish(Progress("map-b", k));
  got = b->Next(absl::Seconds(5));
  ASSERT_EQ(got.events.size(), 4u);
  EXPECT_EQ(got.dropped, 2);
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(got.events[0], &e).ok());
  EXPECT_EQ(e.progress().waypoint(), 3);
  // A subscription ended frees its place.
  a2.reset();
  EXPECT_NE(hub.Subscribe("map-c"), nullptr);
  // Close wakes a waiting subscriber at once.
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    hub.Close();
  });
  const absl::Time t0 = absl::Now();
  got = a->Next(absl::Seconds(30));
  closer.join();
  EXPECT_TRUE(got.closed);
  EXPECT_LT(absl::Now() - t0, absl::Seconds(20));
  EXPECT_EQ(hub.Subscribe("map-a"), nullptr) << "closed for good";
}

constexpr char kAlpha[] = "token-alpha";
constexpr char kBeta[] = "token-beta";

class LiveStreamTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "covplan_live_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.http_port = 0;
    config.store_dir = dir_ + "/maps";
    config.token_file = dir_ + "/tokens.txt";
    std::ofstream(config.token_file) << Sha256Hex(kAlpha) << " alpha\n"
                                     << Sha256Hex(kBeta) << " beta\n";
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_->port()), grpc::InsecureChannelCredentials()));
  }
  void TearDown() override {
    stub_.reset();
    server_.reset();
    std::filesystem::remove_all(dir_);
  }
  std::unique_ptr<grpc::ClientContext> Ctx(const std::string& token) {
    auto c = std::make_unique<grpc::ClientContext>();
    c->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    c->AddMetadata("authorization", absl::StrCat("Bearer ", token));
    return c;
  }
  std::string PutTwoRooms(const std::string& token) {
    v1::PutMapRequest put;
    *put.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.05);
    v1::PutMapResponse stored;
    EXPECT_TRUE(stub_->PutMap(Ctx(token).get(), put, &stored).ok());
    return stored.info().map_id();
  }
  std::unique_ptr<HttpStream> Watch(const std::string& map_id, const std::string& token) {
    absl::StatusOr<std::unique_ptr<HttpStream>> s =
        HttpStream::Open(server_->http_port(), "/v1/events?map_id=" + map_id,
                         {absl::StrCat("Authorization: Bearer ", token)});
    EXPECT_TRUE(s.ok()) << s.status();
    return s.ok() ? std::move(*s) : nullptr;
  }
  // The LiveEvents on the stream's `data:` lines so far.
  static std::vector<v1::LiveEvent> Events(const HttpStream& s) {
    std::vector<v1::LiveEvent> out;
    for (absl::string_view line : absl::StrSplit(s.received(), '\n')) {
      if (!absl::ConsumePrefix(&line, "data: ")) continue;
      v1::LiveEvent e;
      EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(std::string(line), &e).ok()) << line;
      out.push_back(e);
    }
    return out;
  }

  std::string dir_;
  std::unique_ptr<CovplanServer> server_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(LiveStreamTest, AWatcherSeesTheRobotDriveReportGetItsNewPlanAndEnd) {
  const std::string map_id = PutTwoRooms(kAlpha);
  v1::PlanResponse plan;
  ASSERT_TRUE(stub_->Plan(Ctx(kAlpha).get(), PlanRequestFor(map_id, 0.3), &plan).ok());
  std::unique_ptr<HttpStream> watch = Watch(map_id, kAlpha);
  ASSERT_NE(watch, nullptr);
  ASSERT_TRUE(watch->ReadUntil(": live events of map", absl::Seconds(30))) << watch->received();
  EXPECT_NE(watch->received().find("Content-Type: text/event-stream"), std::string::npos);

  auto context = Ctx(kAlpha);
  auto stream = stub_->Drive(context.get());
  v1::DriveRequest first;
  first.set_plan_id(plan.plan_id());
  first.set_sequence(1);
  ASSERT_TRUE(stream->Write(first));
  v1::DriveEvent event;
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_ready());
  for (int k = 1; k <= 3; ++k) {
    v1::DriveRequest at;
    at.set_sequence(1 + k);
    at.mutable_progress()->set_waypoint(k);
    *at.mutable_progress()->mutable_position() = [&] {
      v1::Point2 p;
      p.set_x(plan.path(k - 1).x());
      p.set_y(plan.path(k - 1).y());
      return p;
    }();
    ASSERT_TRUE(stream->Write(at));
  }
  // An obstacle on a cell the plan sweeps late: a new plan comes back.
  const v1::CoverageSweep& late = plan.sweeps(plan.sweeps_size() - 1);
  v1::DriveRequest seen;
  seen.set_sequence(5);
  seen.mutable_progress()->set_waypoint(3);
  seen.mutable_progress()->mutable_position()->set_x(plan.path(2).x());
  seen.mutable_progress()->mutable_position()->set_y(plan.path(2).y());
  v1::CellRef* cell = seen.mutable_obstacles()->add_cells();
  cell->set_row(late.cells(0) / plan.grid().cols());
  cell->set_col(late.cells(0) % plan.grid().cols());
  ASSERT_TRUE(stream->Write(seen));
  ASSERT_TRUE(stream->Read(&event));
  ASSERT_TRUE(event.has_replan()) << event.DebugString();
  ASSERT_TRUE(stream->WritesDone());
  ASSERT_TRUE(stream->Finish().ok());

  ASSERT_TRUE(watch->ReadUntil("\"ended\"", absl::Seconds(30))) << watch->received();
  const std::vector<v1::LiveEvent> events = Events(*watch);
  std::vector<std::string> kinds;
  for (const v1::LiveEvent& e : events) {
    EXPECT_EQ(e.map_id(), map_id);
    EXPECT_GT(e.time_unix_s(), 1.6e9);
    kinds.push_back(e.has_started()     ? "started"
                    : e.has_progress()  ? absl::StrCat("progress ", e.progress().waypoint())
                    : e.has_obstacles() ? "obstacles"
                    : e.has_replan()    ? "replan"
                    : e.has_ended()     ? absl::StrCat("ended ", e.ended().status())
                                        : "?");
  }
  EXPECT_EQ(kinds, (std::vector<std::string>{"started", "progress 1", "progress 2", "progress 3",
                                             "obstacles", "progress 3", "replan", "ended OK"}));
  ASSERT_EQ(events.size(), 8u);
  EXPECT_EQ(events[0].plan_id(), plan.plan_id());
  EXPECT_EQ(events[4].obstacles().cells(0).row(), cell->row());
  const v1::LiveReplan& replan = events[6].replan();
  EXPECT_EQ(replan.previous_plan_id(), plan.plan_id());
  EXPECT_EQ(events[6].plan_id(), event.replan().plan().plan_id());
  EXPECT_EQ(replan.replan().method(), event.replan().replan().method());
  EXPECT_GT(replan.compute_ms(), 0.0);
  EXPECT_EQ(events[7].plan_id(), event.replan().plan().plan_id());
  for (const v1::LiveEvent& e : events) EXPECT_EQ(e.session_id(), events[0].session_id());
}

TEST_F(LiveStreamTest, OnlyCallersWhoMayReadTheMapWatchIt) {
  const std::string map_id = PutTwoRooms(kAlpha);
  // Another tenant's map is not found; no token is unauthenticated.
  absl::StatusOr<HttpReply> other =
      HttpRequest(server_->http_port(), "GET", "/v1/events?map_id=" + map_id,
                  {absl::StrCat("Authorization: Bearer ", kBeta)});
  ASSERT_TRUE(other.ok()) << other.status();
  EXPECT_EQ(other->status, 404) << other->body;
  absl::StatusOr<HttpReply> anonymous =
      HttpRequest(server_->http_port(), "GET", "/v1/events?map_id=" + map_id);
  ASSERT_TRUE(anonymous.ok());
  EXPECT_EQ(anonymous->status, 401);
  absl::StatusOr<HttpReply> no_map = HttpRequest(server_->http_port(), "GET", "/v1/events",
                                                 {absl::StrCat("Authorization: Bearer ", kAlpha)});
  ASSERT_TRUE(no_map.ok());
  EXPECT_EQ(no_map->status, 400);
  EXPECT_NE(no_map->body.find("map_id"), std::string::npos) << no_map->body;
  // The token is checked at the door, before the method: 401 without one.
  absl::StatusOr<HttpReply> post = HttpRequest(server_->http_port(), "POST", "/v1/events",
                                               {"Content-Type: application/json"}, "{}");
  ASSERT_TRUE(post.ok());
  EXPECT_EQ(post->status, 401);
  post = HttpRequest(
      server_->http_port(), "POST", "/v1/events",
      {"Content-Type: application/json", absl::StrCat("Authorization: Bearer ", kAlpha)}, "{}");
  ASSERT_TRUE(post.ok());
  EXPECT_EQ(post->status, 405);
  // The streams are bounded (max_live_streams, 4 by default): the fifth
  // waits for a place (503) while the API goes on answering.
  std::vector<std::unique_ptr<HttpStream>> watchers;
  for (int i = 0; i < 4; ++i) {
    watchers.push_back(Watch(map_id, kAlpha));
    ASSERT_TRUE(watchers.back()->ReadUntil(": live events", absl::Seconds(30)));
  }
  absl::StatusOr<HttpReply> fifth =
      HttpRequest(server_->http_port(), "GET", "/v1/events?map_id=" + map_id,
                  {absl::StrCat("Authorization: Bearer ", kAlpha)});
  ASSERT_TRUE(fifth.ok());
  EXPECT_EQ(fifth->status, 503) << fifth->body;
  absl::StatusOr<HttpReply> listed = HttpRequest(
      server_->http_port(), "POST", "/v1/ListMaps",
      {"Content-Type: application/json", absl::StrCat("Authorization: Bearer ", kAlpha)}, "{}");
  ASSERT_TRUE(listed.ok());
  EXPECT_EQ(listed->status, 200);
  // A watcher that leaves frees its place (found at the stream's next write).
  watchers.pop_back();
  bool admitted = false;
  for (int i = 0; i < 100 && !admitted; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    absl::StatusOr<std::unique_ptr<HttpStream>> again =
        HttpStream::Open(server_->http_port(), "/v1/events?map_id=" + map_id,
                         {absl::StrCat("Authorization: Bearer ", kAlpha)});
    ASSERT_TRUE(again.ok());
    admitted = (*again)->ReadUntil(": live events", absl::Seconds(2));
  }
  EXPECT_TRUE(admitted);
}

}  // namespace
}  // namespace covplan
