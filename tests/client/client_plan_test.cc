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
  s->clear_floor_ms();
}

void AddBox(google::protobuf::RepeatedPtrField<v1::Polygon>* out, double x0, double y0, double x1,
            double y1) {
  v1::Ring* ring = out->Add()->mutable_outer();
  for (auto [x, y] : {std::pair{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}}) {
    v1::Point2* p = ring->add_points();
    p->set_x(x);
    p->set_y(y);
  }
}

// The same request gives the same plan through --local and through the
// server: identical ranks, visiting order and path for the same seed when the
// search converges. Only ids and timings may differ.
TEST(ClientPlanTest, LocalAndServerGiveTheSamePlanForShippedMaps) {
  struct Case {
    const char* map;
    v1::TourSolver tour;
    bool zones;
  };
  for (const Case& c : {Case{"maps/small_rooms.yaml", v1::GREEDY, false},
                        Case{"maps/sample_office.yaml", v1::GTSP, false},
                        Case{"maps/sample_office.yaml", v1::GTSP, true},
                        Case{"maps/sample_yard.geojson", v1::GTSP, true}}) {
    SCOPED_TRACE(absl::StrCat(c.map, c.zones ? " with zones" : ""));
    const std::string path = absl::StrCat(COVPLAN_SOURCE_DIR, "/", c.map);
    absl::StatusOr<v1::Map> map = MapProtoFromFile(path, MapFileOverrides(), EngineLimits());
    ASSERT_TRUE(map.ok()) << map.status();
    v1::PlanRequest request;
    request.mutable_robot()->set_tool_width_m(0.8);
    request.set_tour_solver(c.tour);
    request.set_seed(3);
    request.set_time_limit_s(30);  // the default effort converges long before
    if (c.zones) {
      AddBox(request.mutable_no_go(), 3.3, 3.3, 5.1, 5.05);
      AddBox(request.mutable_regions(), -0.5, 0.2, 21.0, 9.0);
    }
    *request.mutable_map() = *map;
    absl::StatusOr<v1::PlanResponse> local = PlanLocally(request, EngineLimits());
    ASSERT_TRUE(local.ok()) << local.status();
    EXPECT_GT(local->stats().num_ranks(), 0);
    EXPECT_GT(local->stats().covered_free_area_ratio(), 0.5);

    std::string store =
        (std::filesystem::temp_directory_path() / absl::StrCat("covplan_client_plan_", ::getpid()))
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
    EXPECT_EQ(local->termination().reason(), v1::CONVERGED);
    EXPECT_EQ(remote.termination().reason(), v1::CONVERGED);
    EXPECT_GT(remote.path_size(), 10);
    EXPECT_EQ(remote.no_go_size(), c.zones ? 1 : 0);
    v1::PlanResponse a = *local, b = remote;
    Normalise(&a);
    Normalise(&b);
    EXPECT_EQ(*PlanToJson(a), *PlanToJson(b));
    const std::string json = *PlanToJson(*local);
    EXPECT_THAT(json, HasSubstr("\"covered_free_area_ratio\""));
    EXPECT_THAT(json, HasSubstr("\"kind\": \"TRANSITION\""));
  }
}

TEST(ClientPlanTest, PartitionFlagSelectsTheSolverAndTheDefaultIsPushRelabel) {
  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml");
  const std::string out = (std::filesystem::temp_directory_path() /
                           absl::StrCat("covplan_partition_flag_", ::getpid(), ".json"))
                              .string();
  auto solver_of = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"--map", map, "--local", "--tour", "greedy", "--out", out};
    args.insert(args.end(), extra.begin(), extra.end());
    EXPECT_EQ(RunPlanCommand(args), 0);
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    v1::PlanResponse r;
    EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(ss.str(), &r).ok());
    return std::make_pair(r.stats().partition_solver(), r.stats().num_ranks());
  };
  const auto [default_solver, ranks] = solver_of({});
  EXPECT_EQ(default_solver, "pushrelabel");
  for (const char* name : {"pushrelabel", "matching", "mincut", "lp"}) {
    const auto [solver, solver_ranks] = solver_of({"--partition", name});
    EXPECT_EQ(solver, name);
    EXPECT_EQ(solver_ranks, ranks) << name;
  }
  EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--partition", "bk"}), 0);
  std::filesystem::remove(out);
}

TEST(ClientPlanTest, StartAndEndPoseFlagsReachThePlanAndUnreachableCellsAreReported) {
  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml");
  const std::string out =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_pose_", ::getpid(), ".json"))
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
  EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--tour", "greedy", "--start", "-100,-100"}),
            0);
}

TEST(ClientPlanTest, RegionAndNoGoFlagsTakeRingsAndGeoJsonFiles) {
  const std::string yard = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_yard.geojson");
  const std::string zones = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_yard_no_go.geojson");
  const std::string dir =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_zones_", ::getpid()))
          .string();
  std::filesystem::create_directories(dir);
  const std::string out = dir + "/plan.json", svg = dir + "/plan.svg";
  ASSERT_EQ(RunPlanCommand({"--map", yard, "--local", "--tool-width", "0.6", "--tour", "greedy",
                            "--no-go", zones, "--no-go", "10,5 12,5 12,6.5", "--region",
                            "0,0 24,0 24,14 0,14", "--out", out, "--svg", svg}),
            0);
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  v1::PlanResponse r;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(ss.str(), &r).ok());
  EXPECT_EQ(r.no_go_size(), 2);
  EXPECT_EQ(r.regions_size(), 1);
  // The open ring given on the command line was closed for the user.
  EXPECT_EQ(r.no_go(1).outer().points_size(), 4);
  EXPECT_GT(r.stats().no_go_cells(), 0);
  EXPECT_EQ(r.stats().covered_cells(), r.stats().free_cells());
  std::ifstream svg_in(svg);
  std::stringstream svg_text;
  svg_text << svg_in.rdbuf();
  EXPECT_THAT(svg_text.str(), HasSubstr("no-go zones"));
  EXPECT_THAT(svg_text.str(), HasSubstr("regions"));
  // Bad areas: a non-point token, a self-intersecting ring, a missing file.
  EXPECT_NE(RunPlanCommand({"--map", yard, "--local", "--no-go", "1,1 2,x 3,3"}), 0);
  EXPECT_NE(RunPlanCommand({"--map", yard, "--local", "--no-go", "1,1 3,1 1,3 3,3"}), 0);
  EXPECT_NE(RunPlanCommand({"--map", yard, "--local", "--region", "/no/such/zones.geojson"}), 0);
  std::filesystem::remove_all(dir);
}

// `--algorithm stc` (the alias of --planner) plans the same locally and
// through a server; bad STC options are INVALID_ARGUMENT naming the field.
TEST(ClientPlanTest, StcPlansTheSameLocallyAndThroughTheServer) {
  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml");
  const std::string dir =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_client_stc_", ::getpid()))
          .string();
  std::filesystem::create_directories(dir);
  ServerConfig config;
  config.port = 0;
  config.metrics_port = -1;
  config.store_dir = dir + "/store";
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
  ASSERT_TRUE(server.ok()) << server.status();
  const std::string address = absl::StrCat("127.0.0.1:", (*server)->port());
  const std::string local = dir + "/local.json", remote = dir + "/remote.json";
  ASSERT_EQ(RunPlanCommand({"--map", map, "--local", "--algorithm", "stc", "--stc-tree", "prim",
                            "--sweep-direction", "vertical", "--out", local}),
            0);
  ASSERT_EQ(RunPlanCommand({"--map", map, "--server", address, "--planner", "stc", "--stc-tree",
                            "prim", "--sweep-direction", "vertical", "--out", remote}),
            0);
  auto read = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    v1::PlanResponse r;
    EXPECT_TRUE(google::protobuf::util::JsonStringToMessage(ss.str(), &r).ok()) << path;
    return r;
  };
  v1::PlanResponse a = read(local), b = read(remote);
  EXPECT_EQ(a.planner(), "stc");
  ASSERT_TRUE(a.has_stc());
  EXPECT_EQ(a.stc().tree(), v1::STC_TREE_PRIM);
  EXPECT_EQ(a.stats().covered_cells(), a.stats().free_cells());
  Normalise(&a);
  Normalise(&b);
  a.clear_map_id();  // the server names stored maps by content too, but normalise anyway
  b.clear_map_id();
  EXPECT_EQ(*PlanToJson(a), *PlanToJson(b));

  // Through the RPC: a bad tree value and STC options for OARP.
  auto stub = v1::CoveragePlanner::NewStub(
      grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  absl::StatusOr<v1::Map> proto_map = MapProtoFromFile(map, MapFileOverrides(), EngineLimits());
  ASSERT_TRUE(proto_map.ok());
  v1::PlanRequest request;
  *request.mutable_map() = *proto_map;
  request.mutable_robot()->set_tool_width_m(0.8);
  request.set_planner("stc");
  request.mutable_stc()->set_tree(static_cast<v1::StcTree>(42));
  v1::PlanResponse reply;
  {
    grpc::ClientContext context;
    const grpc::Status status = stub->Plan(&context, request, &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("stc.tree"));
  }
  request.set_planner("oarp");
  request.mutable_stc()->set_tree(v1::STC_TREE_PRIM);
  {
    grpc::ClientContext context;
    const grpc::Status status = stub->Plan(&context, request, &reply);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  }
  EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--planner", "oarp", "--algorithm", "stc"}),
            0);
  EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--stc-tree", "prim"}),
            0);  // not the stc planner
  EXPECT_NE(RunPlanCommand({"--map", map, "--local", "--algorithm", "stc", "--stc-tree", "bfs"}),
            0);
  server->reset();
  std::filesystem::remove_all(dir);
}

// `covplan plan --server ... --robot ...`: the fleet is planned by the
// server's PlanFleet; --out is its PlanFleetResponse, whose robots together
// sweep every cell, and whose plan ids the server answers GetPlan for.
TEST(ClientPlanTest, AFleetThroughTheServerHasRetainedPlans) {
  const std::string map = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml");
  const std::string dir =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_client_fleet_", ::getpid()))
          .string();
  std::filesystem::create_directories(dir);
  ServerConfig config;
  config.port = 0;
  config.metrics_port = -1;
  config.store_dir = dir + "/store";
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
  ASSERT_TRUE(server.ok()) << server.status();
  const std::string address = absl::StrCat("127.0.0.1:", (*server)->port());
  const std::string out = dir + "/fleet.json";
  ::testing::internal::CaptureStdout();
  const int rc =
      RunPlanCommand({"--map", map, "--server", address, "--tool-width", "0.8", "--time-limit", "1",
                      "--robot", "1.2,1.2", "--robot", "east=8.4,6", "--out", out});
  const std::string summary = ::testing::internal::GetCapturedStdout();
  ASSERT_EQ(rc, 0);
  EXPECT_THAT(summary, HasSubstr("mission    mission-"));
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  v1::PlanFleetResponse fleet;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(ss.str(), &fleet).ok()) << ss.str();
  ASSERT_EQ(fleet.robots_size(), 2);
  EXPECT_EQ(fleet.robots(1).id(), "east");
  EXPECT_EQ(fleet.covered_cells(), fleet.cover_cells());
  auto stub = v1::CoveragePlanner::NewStub(
      grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  int64_t swept = 0;
  for (const v1::FleetRobotPlan& robot : fleet.robots()) {
    swept += robot.plan().stats().covered_cells();
    v1::GetPlanRequest get;
    get.set_plan_id(robot.plan().plan_id());
    v1::PlanResponse got;
    grpc::ClientContext context;
    ASSERT_TRUE(stub->GetPlan(&context, get, &got).ok()) << robot.plan().plan_id();
    EXPECT_EQ(got.path_size(), robot.plan().path_size());
  }
  EXPECT_GE(swept, fleet.cover_cells());
  server->reset();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace covplan
