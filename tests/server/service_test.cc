// In-process gRPC tests of the covplan service: PutMap then Plan round trip,
// idempotent PutMap, the registry RPCs, every bad input answered with
// INVALID_ARGUMENT and a useful message, health, reflection and /metrics,
// limits and deadlines (remembered plans: remembered_plans_test.cc).
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/service_fixture.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::PlanRequestFor;
using ::covplan::testing::RasterMap;
using ::covplan::testing::TwoRooms;
using ::testing::Contains;
using ::testing::HasSubstr;
using ServiceTest = ::covplan::testing::ServiceTest;

TEST_F(ServiceTest, PutMapThenPlanCoversEveryFreeCell) {
  const std::string map_id = PutTwoRooms();
  ASSERT_EQ(map_id.size(), 64u);
  v1::PlanResponse plan;
  const grpc::Status status = Plan(PlanRequestFor(map_id, 0.4), &plan);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(plan.map_id(), map_id);
  EXPECT_FALSE(plan.plan_id().empty());
  // 0.4 m cells over 0.4 m characters: the grid is the ASCII picture.
  EXPECT_EQ(plan.grid().rows(), 8);
  EXPECT_EQ(plan.grid().cols(), 12);
  EXPECT_EQ(plan.grid().free_cells(0), "000000000000");
  EXPECT_EQ(plan.grid().free_cells(3), "011110110110");  // "#....#..#..#" is row 3 from the bottom
  int free_cells = 0;
  for (const std::string& row : plan.grid().free_cells()) {
    free_cells += static_cast<int>(std::count(row.begin(), row.end(), '1'));
  }
  EXPECT_EQ(plan.stats().free_cells(), free_cells);
  int cells_in_ranks = 0;
  for (const v1::Rank& rank : plan.ranks()) {
    cells_in_ranks += rank.orientation() == v1::HORIZONTAL
                          ? rank.last_cell().col() - rank.first_cell().col() + 1
                          : rank.last_cell().row() - rank.first_cell().row() + 1;
  }
  EXPECT_EQ(cells_in_ranks, free_cells);
  EXPECT_EQ(plan.stats().num_ranks(), plan.ranks_size());
  EXPECT_EQ(plan.rank_order_size(), plan.ranks_size());
  ASSERT_GT(plan.path_size(), 1);
  EXPECT_EQ(plan.path(0).kind(), v1::START);
  EXPECT_GT(plan.stats().coverage_length_m(), 0);
  EXPECT_FALSE(plan.stats().decomposition_cached());

  // Same request again: the decomposition comes from the cache.
  v1::PlanResponse again;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &again).ok());
  EXPECT_TRUE(again.stats().decomposition_cached());
  EXPECT_EQ(again.ranks_size(), plan.ranks_size());
  EXPECT_NE(again.plan_id(), plan.plan_id());

  // The plan stays addressable by its id.
  v1::PlanResponse retained;
  ASSERT_TRUE(GetPlan(plan.plan_id(), &retained).ok());
  EXPECT_EQ(retained.SerializeAsString(), plan.SerializeAsString());
}

void AddRing(v1::Ring* ring, std::vector<std::pair<double, double>> pts) {
  for (auto [x, y] : pts) {
    v1::Point2* p = ring->add_points();
    p->set_x(x);
    p->set_y(y);
  }
}

TEST_F(ServiceTest, PolygonMapsRegionsAndNoGoZonesOverGrpc) {
  v1::Map map;
  v1::Polygon* site = map.mutable_polygons()->add_polygons();
  AddRing(site->mutable_outer(), {{0, 0}, {12, 0}, {12, 8}, {0, 8}, {0, 0}});
  AddRing(site->add_holes(), {{5, 3}, {7, 3}, {7, 5}, {5, 5}, {5, 3}});
  v1::PutMapResponse put;
  ASSERT_TRUE(PutMap(map, &put).ok());
  EXPECT_NEAR(put.info().free_area_m2(), 96 - 4, 1e-9);
  v1::PlanRequest request = PlanRequestFor(put.map_id(), 0.5);
  request.set_time_limit_s(30);  // converges long before, even on a loaded machine
  AddRing(request.add_no_go()->mutable_outer(), {{1, 1}, {2.3, 1}, {2.3, 2.2}, {1, 1}});
  AddRing(request.add_regions()->mutable_outer(), {{0, 0}, {9, 0}, {9, 8}, {0, 8}, {0, 0}});
  v1::PlanResponse plan;
  const grpc::Status status = Plan(request, &plan);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(plan.planner(), "oarp");
  EXPECT_GT(plan.stats().no_go_cells(), 0);
  EXPECT_EQ(plan.stats().covered_cells(), plan.stats().free_cells());
  EXPECT_EQ(plan.no_go_size(), 1);
  EXPECT_EQ(plan.regions_size(), 1);
  EXPECT_EQ(plan.termination().reason(), v1::CONVERGED);
  int coverage = 0;
  for (const v1::Waypoint& w : plan.path()) coverage += w.kind() == v1::COVERAGE;
  EXPECT_EQ(plan.sweeps_size(), coverage);
  // Nothing east of the region (x > 9) is swept.
  for (const v1::CoverageSweep& s : plan.sweeps()) {
    for (int32_t cell : s.cells()) {
      const int col = cell % plan.grid().cols();
      EXPECT_LT(plan.grid().origin_x_m() + (col + 0.5) * 0.5, 9.0);
    }
  }
  // GetPlan returns the retained plan, zones included.
  v1::PlanResponse retained;
  ASSERT_TRUE(GetPlan(plan.plan_id(), &retained).ok());
  EXPECT_EQ(retained.SerializeAsString(), plan.SerializeAsString());

  // Bad geometry: INVALID_ARGUMENT naming the ring.
  v1::Map bow_tie;
  AddRing(bow_tie.mutable_polygons()->add_polygons()->mutable_outer(),
          {{0, 0}, {4, 0}, {0, 4}, {4, 4}, {0, 0}});
  v1::PutMapResponse bad_put;
  grpc::Status bad = PutMap(bow_tie, &bad_put);
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(bad.error_message(), HasSubstr("map.polygons[0].outer"));
  v1::PlanRequest open_zone = PlanRequestFor(put.map_id(), 0.5);
  AddRing(open_zone.add_no_go()->mutable_outer(), {{1, 1}, {2, 1}, {2, 2}});
  bad = Plan(open_zone, &plan);
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(bad.error_message(), HasSubstr("no_go[0].outer: ring is not closed"));
  v1::PlanRequest unknown = PlanRequestFor(put.map_id(), 0.5);
  unknown.set_planner("stc-not-yet");
  bad = Plan(unknown, &plan);
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(bad.error_message(), HasSubstr("unknown planner"));
}

TEST_F(ServiceTest, InlineMapPlansWithoutPutMap) {
  v1::PlanRequest request = PlanRequestFor("", 0.4);
  *request.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1);
  v1::PlanResponse plan;
  const grpc::Status status = Plan(request, &plan);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(plan.map_id(), ComputeMapId(request.map()));
  EXPECT_GT(plan.ranks_size(), 0);
}

TEST_F(ServiceTest, PutMapIsIdempotentAndRegistryWorks) {
  const v1::Map map = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1);
  v1::PutMapResponse first, second;
  ASSERT_TRUE(PutMap(map, &first).ok());
  ASSERT_TRUE(PutMap(map, &second).ok());
  EXPECT_EQ(first.map_id(), second.map_id());
  EXPECT_TRUE(first.created());
  EXPECT_FALSE(second.created());
  EXPECT_EQ(second.info().width_px(), 48);
  EXPECT_EQ(second.info().height_px(), 32);
  EXPECT_EQ(second.info().name(), "two rooms");

  {
    grpc::ClientContext context;
    v1::ListMapsResponse list;
    ASSERT_TRUE(stub_->ListMaps(&context, v1::ListMapsRequest(), &list).ok());
    ASSERT_EQ(list.maps_size(), 1);
    EXPECT_EQ(list.maps(0).map_id(), first.map_id());
  }
  {
    grpc::ClientContext context;
    v1::GetMapRequest get;
    get.set_map_id(first.map_id());
    get.set_include_content(true);
    v1::GetMapResponse got;
    ASSERT_TRUE(stub_->GetMap(&context, get, &got).ok());
    EXPECT_EQ(got.map().raster().image(), map.raster().image());
  }
  {
    grpc::ClientContext context;
    v1::DeleteMapRequest del;
    del.set_map_id(first.map_id());
    v1::DeleteMapResponse deleted;
    ASSERT_TRUE(stub_->DeleteMap(&context, del, &deleted).ok());
    EXPECT_TRUE(deleted.deleted());
  }
  v1::PlanResponse plan;
  const grpc::Status status = Plan(PlanRequestFor(first.map_id(), 0.4), &plan);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(status.error_message(), HasSubstr("unknown map_id"));
}

struct BadInput {
  std::string name;
  std::function<void(v1::PlanRequest*)> mutate;
  std::string message;
};

TEST_F(ServiceTest, EveryBadInputIsInvalidArgumentWithAMessage) {
  const std::string pgm = AsciiToPgm(TwoRooms(), 4);
  const std::vector<BadInput> cases = {
      {"zero resolution", [&](v1::PlanRequest* r) { *r->mutable_map() = RasterMap(pgm, 0); },
       "resolution"},
      {"negative resolution", [&](v1::PlanRequest* r) { *r->mutable_map() = RasterMap(pgm, -1); },
       "resolution"},
      {"NaN resolution",
       [&](v1::PlanRequest* r) { *r->mutable_map() = RasterMap(pgm, std::nan("")); }, "resolution"},
      {"zero tool width", [](v1::PlanRequest* r) { r->mutable_robot()->set_tool_width_m(0); },
       "tool_width_m"},
      {"negative tool width",
       [](v1::PlanRequest* r) { r->mutable_robot()->set_tool_width_m(-0.4); }, "tool_width_m"},
      {"NaN tool width",
       [](v1::PlanRequest* r) { r->mutable_robot()->set_tool_width_m(std::nan("")); },
       "tool_width_m"},
      {"tool narrower than a pixel",
       [](v1::PlanRequest* r) { r->mutable_robot()->set_tool_width_m(0.05); },
       "narrower than one map pixel"},
      {"tool wider than the map",
       [](v1::PlanRequest* r) { r->mutable_robot()->set_tool_width_m(10); }, "wider than the map"},
      {"no free cell",
       [](v1::PlanRequest* r) {
         *r->mutable_map() = RasterMap(AsciiToPgm({"####", "####"}, 4), 0.1);
       },
       "no free"},
      {"image too large",
       [](v1::PlanRequest* r) {
         *r->mutable_map() =
             RasterMap(AsciiToPgm(std::vector<std::string>(80, std::string(80, '.')), 16), 0.01);
       },
       "too large"},
      {"corrupt image",
       [&](v1::PlanRequest* r) { *r->mutable_map() = RasterMap(pgm.substr(0, 40), 0.1); },
       "map.raster.image"},
      {"not an image",
       [](v1::PlanRequest* r) { *r->mutable_map() = RasterMap("hello world", 0.1); },
       "neither a PGM"},
      {"corrupt YAML",
       [&](v1::PlanRequest* r) {
         *r->mutable_map() = RasterMap(pgm, 0.1);
         r->mutable_map()->mutable_raster()->clear_resolution();
         r->mutable_map()->mutable_raster()->set_yaml("resolution: [0.1\norigin: {");
       },
       "map.raster.yaml"},
      {"malformed map_id", [](v1::PlanRequest* r) { r->set_map_id("not-an-id"); }, "malformed"},
      {"no map at all", [](v1::PlanRequest* r) { r->clear_map_ref(); }, "map_id or an inline map"},
  };
  for (const BadInput& c : cases) {
    SCOPED_TRACE(c.name);
    v1::PlanRequest request = PlanRequestFor("", 0.4);
    *request.mutable_map() = RasterMap(pgm, 0.1);
    c.mutate(&request);
    v1::PlanResponse response;
    const grpc::Status status = Plan(request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(c.message));
  }
  // PutMap validates the map too.
  v1::PutMapResponse put;
  const grpc::Status status = PutMap(RasterMap(pgm.substr(0, 30), 0.1), &put);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("map.raster.image"));
}

// Random mixes of valid and hostile field values (NaN, infinities, zero,
// negative, huge, tiny, unknown enum numbers, poses outside the map): every
// request gets OK with a complete plan or INVALID_ARGUMENT with a message,
// and the server keeps serving.
TEST_F(ServiceTest, RandomHostileRequestsAreAnsweredNeverCrash) {
  const std::string map_id = PutTwoRooms();
  const std::string pgm = AsciiToPgm(TwoRooms(), 4);
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> hostile = {
      0.0, -1.0, nan, inf, -inf, 1e300, 1e-300, -0.0, std::numeric_limits<double>::denorm_min()};
  std::mt19937 rng(20261122);
  auto pick = [&](const std::vector<double>& good) {
    return rng() % 3 == 0 ? hostile[rng() % hostile.size()] : good[rng() % good.size()];
  };
  std::map<int, int> codes;
  for (int i = 0; i < 150; ++i) {
    SCOPED_TRACE(i);
    v1::PlanRequest request = PlanRequestFor(map_id, 0.4);
    if (rng() % 4 == 0) {
      *request.mutable_map() = RasterMap(pgm, pick({0.1, 0.05}));
      if (rng() % 2) request.mutable_map()->mutable_raster()->set_origin_x_m(pick({-3.0, 2.5}));
      if (rng() % 2) request.mutable_map()->mutable_raster()->set_free_thresh(pick({0.1, 0.3}));
      if (rng() % 2) request.mutable_map()->mutable_raster()->set_occupied_thresh(pick({0.6, 0.9}));
    }
    v1::RobotModel* robot = request.mutable_robot();
    robot->set_tool_width_m(pick({0.3, 0.4, 0.6}));
    if (rng() % 2) robot->set_max_speed_mps(pick({0.5, 1.0, 2.0}));
    if (rng() % 2) robot->set_acceleration_mps2(pick({0.2, 0.5}));
    if (rng() % 2) robot->set_turn_rate_deg_s(pick({30.0, 90.0}));
    if (rng() % 3 == 0) {
      robot->mutable_start()->set_x(pick({0.5, 1.5, 50.0}));
      robot->mutable_start()->set_y(pick({0.5, 1.0, -20.0}));
      robot->mutable_start()->set_theta(pick({0.0, 3.0, 100.0}));
    }
    if (rng() % 4 == 0) {
      robot->mutable_end()->set_x(pick({1.0, 2.0}));
      robot->mutable_end()->set_y(pick({0.5, 1.5}));
    }
    request.set_time_limit_s(pick({0.01, 0.05, 0.2}));
    if (rng() % 3 == 0) request.set_min_free_fraction(pick({0.3, 0.5, 0.9, 1.0, 1.5}));
    if (rng() % 5 == 0) request.set_partition_solver(static_cast<v1::PartitionSolver>(rng() % 5));
    if (rng() % 5 == 0) request.set_tour_solver(static_cast<v1::TourSolver>(rng() % 4));
    request.set_seed(rng());

    v1::PlanResponse response;
    const grpc::Status status = Plan(request, &response);
    ++codes[status.error_code()];
    if (status.ok()) {
      ASSERT_EQ(response.rank_order_size(), response.ranks_size());
      std::vector<int> order(response.rank_order().begin(), response.rank_order().end());
      std::sort(order.begin(), order.end());
      for (int r = 0; r < static_cast<int>(order.size()); ++r) ASSERT_EQ(order[r], r);
      for (const v1::Waypoint& w : response.path()) {
        ASSERT_TRUE(std::isfinite(w.x()) && std::isfinite(w.y()) && std::isfinite(w.theta()));
      }
      EXPECT_TRUE(std::isfinite(response.stats().estimated_duration_s()));
      EXPECT_GT(response.stats().estimated_duration_s(), 0.0);
    } else {
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
          << status.error_message() << "\nrequest (map bytes omitted): " << [&] {
               v1::PlanRequest shown = request;
               if (shown.has_map()) shown.mutable_map()->mutable_raster()->clear_image();
               return shown.ShortDebugString();
             }();
      EXPECT_FALSE(status.error_message().empty());
    }
  }
  // Both outcomes were exercised, and the server still plans.
  EXPECT_GT(codes[grpc::StatusCode::OK], 10);
  EXPECT_GT(codes[grpc::StatusCode::INVALID_ARGUMENT], 10);
  v1::PlanResponse response;
  EXPECT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &response).ok());
}

TEST_F(ServiceTest, UnknownMapIdIsNotFound) {
  v1::PlanResponse response;
  const grpc::Status status = Plan(PlanRequestFor(std::string(64, 'a'), 0.4), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(status.error_message(), HasSubstr("PutMap it first"));
}

TEST_F(ServiceTest, HealthIsServingAndReflectionListsTheService) {
  absl::StatusOr<int> health = testing::HealthStatus(channel_, "");
  ASSERT_TRUE(health.ok()) << health.status();
  EXPECT_EQ(*health, 1);  // SERVING
  health = testing::HealthStatus(channel_, "covplan.v1.CoveragePlanner");
  ASSERT_TRUE(health.ok()) << health.status();
  EXPECT_EQ(*health, 1);
  absl::StatusOr<std::vector<std::string>> services = testing::ReflectionServices(channel_);
  ASSERT_TRUE(services.ok()) << services.status();
  EXPECT_THAT(*services, Contains("covplan.v1.CoveragePlanner"));
  EXPECT_THAT(*services, Contains("grpc.health.v1.Health"));
}

class MetricsServiceTest : public ServiceTest {
 protected:
  MetricsServiceTest() { with_metrics_ = true; }
};

TEST_F(MetricsServiceTest, MetricsEndpointExposesTheFamilies) {
  const std::string map_id = PutTwoRooms();
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestFor(map_id, 0.4), &plan).ok());
  ASSERT_GT(server_->metrics_port(), 0);
  absl::StatusOr<std::string> body = testing::HttpGet(server_->metrics_port(), "/metrics");
  ASSERT_TRUE(body.ok()) << body.status();
  for (const char* family :
       {"covplan_requests_total{code=\"OK\",method=\"Plan\"} 1",
        "covplan_request_duration_seconds_bucket{method=\"Plan\"",
        "covplan_plan_solve_duration_seconds_count 1", "covplan_plans_cut_short_total",
        "covplan_worker_queue_depth", "covplan_solves_in_flight",
        "covplan_artifact_cache_misses_total 5",  // grid, area, floor, partition, transitions
        "covplan_plan_source_total{source=\"cold\"} 1",
        "covplan_plan_source_total{source=\"cache_hit\"} 0", "covplan_artifact_cache_hits_total",
        "covplan_artifact_cache_evictions_total", "covplan_artifact_cache_bytes",
        "covplan_maps_stored 1"}) {
    EXPECT_THAT(*body, HasSubstr(family));
  }
}

// 120 x 100 cells of 0.5 m with 300 pillars: hundreds of ranks, seconds of
// transition paths.
v1::Map PillarMap() {
  return RasterMap(AsciiToPgm(testing::PillarField(120, 100, 300, 5), 5), 0.1);
}

// The dense path: its all-pairs transition table is what the deadline cuts
// off (the sparse path plans this map within it).
class DenseServiceTest : public ServiceTest {
 protected:
  DenseServiceTest() { dense_transition_bytes_ = int64_t{1} << 30; }
};

TEST_F(DenseServiceTest, DecompositionCutOffByADeadlineIsFinishedInTheBackground) {
  // 60 x 50 cells of 0.5 m with 80 pillars: a transition table that takes far
  // longer than a 60 ms deadline (25 ms of which are kept for the reply).
  v1::PutMapResponse put;
  ASSERT_TRUE(
      PutMap(RasterMap(AsciiToPgm(testing::PillarField(60, 50, 80, 3), 5), 0.1), &put).ok());
  const v1::PlanRequest request = PlanRequestFor(put.map_id(), 0.5);
  auto plan_within = [&](std::chrono::milliseconds deadline, v1::PlanResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + deadline);
    return stub_->Plan(&context, request, response);
  };
  v1::PlanResponse response;
  grpc::Status status = plan_within(std::chrono::milliseconds(60), &response);
  ASSERT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  // Short calls keep failing only until the background build lands in the
  // cache; then the same short deadline gets a plan from the cached
  // decomposition.
  const absl::Time give_up = absl::Now() + absl::Seconds(120);
  int refused = 0;
  while (absl::Now() < give_up) {
    status = plan_within(std::chrono::milliseconds(150), &response);
    if (status.ok()) break;
    ASSERT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
    ++refused;
    absl::SleepFor(absl::Milliseconds(100));
  }
  ASSERT_TRUE(status.ok()) << "still " << status.error_message() << " after " << refused
                           << " calls";
  EXPECT_TRUE(response.stats().decomposition_cached());
  EXPECT_GT(response.stats().num_ranks(), 0);
  EXPECT_GE(server_->service().cache().stats().misses, 1);
}

class RankLimitServiceTest : public ServiceTest {
 protected:
  RankLimitServiceTest() { max_ranks_ = 100; }
};

TEST_F(RankLimitServiceTest, TooManyRanksIsInvalidArgumentBeforeTheTransitionTable) {
  v1::PutMapResponse put;
  ASSERT_TRUE(PutMap(PillarMap(), &put).ok());
  v1::PlanResponse plan;
  const grpc::Status status = Plan(PlanRequestFor(put.map_id(), 0.5), &plan);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("coverage ranks"));
  EXPECT_THAT(status.error_message(), HasSubstr("limit of 100"));
  // A map within the limit still plans.
  ASSERT_TRUE(Plan(PlanRequestFor(PutTwoRooms(), 0.4), &plan).ok());
}

class RequestTimeLimitServiceTest : public ServiceTest {
 protected:
  // The all-pairs transition table: far longer than 150 ms on PillarMap
  // (the sparse path would plan it within the limit).
  RequestTimeLimitServiceTest() {
    max_request_time_ = absl::Milliseconds(150);
    dense_transition_bytes_ = int64_t{1} << 30;
  }
};

TEST_F(RequestTimeLimitServiceTest, CallWithoutDeadlineStopsAtTheServerLimit) {
  v1::PutMapResponse put;
  ASSERT_TRUE(PutMap(PillarMap(), &put).ok());
  v1::PlanRequest request = PlanRequestFor(put.map_id(), 0.5);
  request.set_time_limit_s(30.0);
  grpc::ClientContext context;  // no deadline
  v1::PlanResponse plan;
  const absl::Time start = absl::Now();
  const grpc::Status status = stub_->Plan(&context, request, &plan);
  const absl::Duration took = absl::Now() - start;
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("--max_request_s"));
  EXPECT_LT(took, absl::Seconds(10));
  // The worker is free again: a small map plans.
  ASSERT_TRUE(Plan(PlanRequestFor(PutTwoRooms(), 0.4), &plan).ok());
}

TEST_F(ServiceTest, DrainingServiceRefusesNewWork) {
  server_->service().StartDraining();
  v1::PutMapResponse put;
  const grpc::Status status = PutMap(RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1), &put);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE);
}

// Battery plans over gRPC: charge cycles in the reply, bad battery input
// refused with INVALID_ARGUMENT naming the field.
TEST_F(ServiceTest, BatteryPlansOverGrpcAndBadBatteryInput) {
  const std::string id = PutTwoRooms();
  v1::PlanRequest request = PlanRequestFor(id, 0.4);
  request.set_planner("boustrophedon");
  v1::Battery* b = request.mutable_battery();
  b->set_capacity(25);
  b->set_reserve(1);
  b->mutable_station()->set_x(1.0);
  b->mutable_station()->set_y(0.6);
  v1::PlanResponse response;
  grpc::Status status = Plan(request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(response.cycles_size(), 2);
  EXPECT_EQ(response.stats().charge_cycles(), response.cycles_size());
  EXPECT_EQ(response.stats().covered_cells(), response.stats().free_cells());
  EXPECT_TRUE(response.has_boustrophedon());
  for (const v1::ChargeCycle& c : response.cycles()) {
    EXPECT_LE(c.energy(), 24.0 + 1e-9);
    EXPECT_DOUBLE_EQ(response.path(c.first_waypoint()).x(), 1.0);
    EXPECT_DOUBLE_EQ(response.path(c.last_waypoint()).y(), 0.6);
  }
  const std::vector<std::pair<std::function<void(v1::Battery*)>, const char*>> bad = {
      {[](v1::Battery* x) { x->set_capacity(0); }, "battery.capacity"},
      {[](v1::Battery* x) { x->set_capacity(-3); }, "battery.capacity"},
      {[](v1::Battery* x) { x->set_capacity(std::nan("")); }, "battery.capacity"},
      {[](v1::Battery* x) { x->set_reserve(25); }, "battery.reserve"},
      {[](v1::Battery* x) { x->clear_station(); }, "battery.station"},
      {[](v1::Battery* x) { x->mutable_station()->set_x(40); }, "outside the map"},
      {[](v1::Battery* x) { x->mutable_station()->set_x(0.2), x->mutable_station()->set_y(0.2); },
       "obstacle"},
      {[](v1::Battery* x) { x->set_capacity(1.5); }, "needs"},
  };
  for (const auto& [mutate, message] : bad) {
    SCOPED_TRACE(message);
    v1::PlanRequest r = request;
    mutate(r.mutable_battery());
    status = Plan(r, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(message));
  }
}

}  // namespace
}  // namespace covplan
