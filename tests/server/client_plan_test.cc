// The CLI's plan path: a shipped map read from disk plans the same through
// --local (PlanLocally) and through the server, and the JSON has the
// plan.json shape.
#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "client/plan_command.h"
#include "gmock/gmock.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

// Drops what legitimately differs between two runs: ids and timings.
void Normalise(v1::PlanResponse* r) {
  r->clear_plan_id();
  v1::PlanStats* s = r->mutable_stats();
  s->clear_planning_ms();
  s->clear_grid_ms();
  s->clear_partition_ms();
  s->clear_transitions_ms();
  s->clear_tour_ms();
  s->clear_decomposition_cached();
}

TEST(ClientPlanTest, LocalAndServerGiveTheSamePlanForShippedMaps) {
  for (const char* name : {"maps/small_rooms.yaml", "maps/sample_office.yaml"}) {
    SCOPED_TRACE(name);
    const std::string path = absl::StrCat(COVPLAN_SOURCE_DIR, "/", name);
    absl::StatusOr<v1::Map> map = MapProtoFromFile(path, MapFileOverrides(), InputLimits());
    ASSERT_TRUE(map.ok()) << map.status();
    v1::PlanRequest request;
    request.mutable_robot()->set_tool_width_m(0.8);
    request.set_tour_solver(v1::GREEDY);  // deterministic and fast
    request.set_seed(3);
    *request.mutable_map() = *map;
    absl::StatusOr<v1::PlanResponse> local = PlanLocally(request, InputLimits());
    ASSERT_TRUE(local.ok()) << local.status();
    EXPECT_GT(local->stats().num_ranks(), 0);
    EXPECT_GT(local->stats().covered_free_area_ratio(), 0.5);

    std::string store = (std::filesystem::temp_directory_path() /
                         absl::StrCat("covplan_client_plan_", ::getpid()))
                            .string();
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.store_dir = store;
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    auto stub = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", (*server)->port()), grpc::InsecureChannelCredentials()));
    v1::PutMapRequest put;
    *put.mutable_map() = *map;
    v1::PutMapResponse stored;
    {
      grpc::ClientContext context;
      ASSERT_TRUE(stub->PutMap(&context, put, &stored).ok());
    }
    request.set_map_id(stored.map_id());
    v1::PlanResponse remote;
    {
      grpc::ClientContext context;
      const grpc::Status status = stub->Plan(&context, request, &remote);
      ASSERT_TRUE(status.ok()) << status.error_message();
    }
    server->reset();
    std::filesystem::remove_all(store);

    EXPECT_EQ(remote.map_id(), local->map_id());
    v1::PlanResponse a = *local, b = remote;
    Normalise(&a);
    Normalise(&b);
    EXPECT_EQ(*PlanToJson(a), *PlanToJson(b));
    const std::string json = *PlanToJson(*local);
    EXPECT_THAT(json, HasSubstr("\"covered_free_area_ratio\""));
    EXPECT_THAT(json, HasSubstr("\"kind\": \"TRANSITION\""));
  }
}

TEST(ClientPlanTest, StartAndEndPoseFlagsReachThePlanAndUnreachableCellsAreReported) {
  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml");
  const std::string out = (std::filesystem::temp_directory_path() /
                           absl::StrCat("covplan_pose_", ::getpid(), ".json"))
                              .string();
  ASSERT_EQ(RunPlanCommand({"--map", map, "--local", "--tour", "greedy", "--out", out}), 0);
  auto read = [&]() {
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    v1::PlanResponse r;
    EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(ss.str(), &r).ok());
    return r;
  };
  const v1::PlanResponse first = read();
  // The office has a small room behind a door narrower than the 0.8 m tool.
  EXPECT_GT(first.stats().unreachable_free_cells(), 0);
  ASSERT_GT(first.path_size(), 10);
  const v1::Waypoint s = first.path(7), e = first.path(first.path_size() / 2);
  const std::string start = absl::StrCat(s.x(), ",", s.y(), ",0.5");
  const std::string end = absl::StrCat(e.x(), ",", e.y());
  ASSERT_EQ(RunPlanCommand({"--map", map, "--local", "--tour", "greedy", "--start", start, "--end",
                            end, "--out", out}),
            0);
  const v1::PlanResponse posed = read();
  EXPECT_NEAR(posed.path(0).x(), s.x(), 1e-9);
  EXPECT_NEAR(posed.path(0).y(), s.y(), 1e-9);
  EXPECT_NEAR(posed.path(0).theta(), 0.5, 1e-9);
  EXPECT_NEAR(posed.path(posed.path_size() - 1).x(), e.x(), 1e-9);
  EXPECT_NEAR(posed.path(posed.path_size() - 1).y(), e.y(), 1e-9);
  EXPECT_EQ(posed.stats().num_ranks(), first.stats().num_ranks());
  std::filesystem::remove(out);

  // Malformed poses and poses off the map are refused with a non-zero exit.
  for (const char* bad : {"1", "1,x", "1,2,3,4", "nan,2", ""}) {
    EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--start", bad}), 0) << bad;
  }
  EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--tour", "greedy", "--start", "-100,-100"}), 0);
}

}  // namespace
}  // namespace covplan
