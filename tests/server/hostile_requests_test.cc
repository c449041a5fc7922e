// The hostile-request generator: seeded random requests to every RPC of a
// real covplan-server (garbage and extreme images, YAML, ids, page tokens,
// robot models, zones, inline plans). Every reply must be OK or a client
// error with a short message (never INTERNAL / UNKNOWN, never a megabyte
// echo), and the server must still plan afterwards.
//
//   COVPLAN_HOSTILE_COUNT=2000 COVPLAN_HOSTILE_SEED=3 bin/hostile_requests_test
//   (scripts/chaos/hostile_requests.sh runs it so)
#include <grpcpp/grpcpp.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <random>

#include "absl/strings/str_cat.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "google/protobuf/stubs/logging.h"
#include "gtest/gtest.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/server_process.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::RasterMap;
using ::covplan::testing::ServerProcess;
using ::covplan::testing::TwoRooms;

const char* CodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return "OK";
    case grpc::StatusCode::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case grpc::StatusCode::NOT_FOUND:
      return "NOT_FOUND";
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION:
      return "FAILED_PRECONDITION";
    case grpc::StatusCode::UNAVAILABLE:
      return "UNAVAILABLE";
    case grpc::StatusCode::INTERNAL:
      return "INTERNAL";
    case grpc::StatusCode::UNKNOWN:
      return "UNKNOWN";
    default:
      return "OTHER";
  }
}

int EnvInt(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::atoi(v) : fallback;
}

class Hostile {
 public:
  explicit Hostile(uint32_t seed) : rng_(seed) {}

  double Number() {
    static const double kSpecial[] = {0.0,
                                      -0.0,
                                      -1.0,
                                      1e-300,
                                      1e300,
                                      -1e308,
                                      1e308,
                                      std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::infinity(),
                                      -std::numeric_limits<double>::infinity(),
                                      std::numeric_limits<double>::denorm_min(),
                                      0.05,
                                      0.4,
                                      3.0};
    if (Chance(0.7)) return kSpecial[Below(std::size(kSpecial))];
    return std::uniform_real_distribution<double>(-1e6, 1e6)(rng_);
  }
  std::string Text() {
    static const size_t kSizes[] = {0, 1, 63, 64, 65, 255, 256, 257, 1024, 1025, 70000, 1 << 20};
    const size_t n = kSizes[Below(std::size(kSizes))];
    std::string s(n, 'a');
    const int kind = Below(4);
    for (char& c : s) {
      c = kind == 0   ? "0123456789abcdef"[Below(16)]
          : kind == 1 ? static_cast<char>(Below(256))
          : kind == 2 ? '/'
                      : 'x';
    }
    if (Chance(0.1)) s = "../../../../etc/passwd";
    return s;
  }
  std::string Image() {
    switch (Below(6)) {
      case 0:
        return Text();
      case 1:
        return "P5\n99999999 99999999\n255\n";
      case 2:
        return "P5\n4 4\n255\n" + std::string(3, '\xfe');  // truncated
      case 3:
        return std::string("\x89PNG\r\n\x1a\n", 8) + Text();
      case 4:
        return "P5\n-3 4\n65536\n" + std::string(64, '\0');
      default:
        return AsciiToPgm(TwoRooms(), 1 + Below(4));
    }
  }
  std::string Yaml() {
    switch (Below(6)) {
      case 0:
        return Text();
      case 1:
        return "resolution: " + std::string(60000, '9');
      case 2:
        return std::string(60000, '[');
      case 3:
        return absl::StrCat("resolution: ", Number(), "\norigin: [", Number(), ", ", Number(),
                            ", 0]\n");
      case 4:
        return absl::StrCat("resolution: 0.1\nnegate: ", Text().substr(0, 8),
                            "\nfree_thresh: ", Number(), "\n");
      default:
        return "";
    }
  }
  v1::Map Map() {
    v1::Map map;
    if (Chance(0.1)) return map;  // no source
    if (Chance(0.15)) {
      v1::Polygon* p = map.mutable_polygons()->add_polygons();
      for (int i = 0, n = Below(6); i < n; ++i) {
        v1::Point2* q = p->mutable_outer()->add_points();
        q->set_x(Number());
        q->set_y(Number());
      }
      map.mutable_polygons()->set_resolution(Number());
      return map;
    }
    map.mutable_raster()->set_image(Image());
    if (Chance(0.5)) map.mutable_raster()->set_yaml(Yaml());
    if (Chance(0.7)) map.mutable_raster()->set_resolution(Chance(0.5) ? 0.1 : Number());
    if (Chance(0.3)) map.mutable_raster()->set_origin_x_m(Number());
    if (Chance(0.3)) map.mutable_raster()->set_free_thresh(Number());
    return map;
  }
  v1::PlanRequest Plan(const std::string& good_map_id) {
    v1::PlanRequest r;
    if (Chance(0.2))
      *r.mutable_map() = Map();
    else
      r.set_map_id(Chance(0.6) ? good_map_id : Text());
    r.mutable_robot()->set_tool_width_m(Chance(0.5) ? 0.4 : Number());
    if (Chance(0.3)) r.mutable_robot()->set_max_speed_mps(Number());
    r.set_time_limit_s(Chance(0.5) ? 0.05 : Number());
    if (Chance(0.2)) r.set_min_free_fraction(Number());
    if (Chance(0.2)) r.set_planner(Text());
    if (Chance(0.2)) {
      v1::Polygon* zone = Chance(0.5) ? r.add_regions() : r.add_no_go();
      for (int i = 0, n = Below(8); i < n; ++i) {
        v1::Point2* q = zone->mutable_outer()->add_points();
        q->set_x(Number());
        q->set_y(Number());
      }
    }
    return r;
  }
  // A fleet on the good map: mostly plausible robots (starts anywhere on the
  // 4.8 x 3.2 m map, walls included), some hostile values.
  v1::PlanFleetRequest Fleet(const std::string& good_map_id) {
    v1::PlanFleetRequest r;
    *r.mutable_plan() = Plan(good_map_id);
    if (Chance(0.5)) r.mutable_plan()->set_map_id(good_map_id);
    if (Chance(0.5)) r.mutable_plan()->clear_planner();
    const int robots = Chance(0.05) ? 70 : Below(5);
    const bool plausible = Chance(0.6);
    for (int i = 0; i < robots; ++i) {
      v1::FleetRobot* robot = r.add_robots();
      robot->set_id(Chance(0.8) ? absl::StrCat("r", i) : Text());
      robot->mutable_robot()->set_tool_width_m(plausible || Chance(0.5) ? 0.4 : Number());
      if (Chance(0.6)) {
        v1::Pose* start = robot->mutable_robot()->mutable_start();
        start->set_x(plausible ? std::uniform_real_distribution<double>(0, 4.8)(rng_) : Number());
        start->set_y(plausible ? std::uniform_real_distribution<double>(0, 3.2)(rng_) : Number());
      }
      if (Chance(0.2)) {
        v1::Battery* battery = robot->mutable_battery();
        battery->set_capacity(plausible ? 20.0 : Number());
        battery->mutable_station()->set_x(plausible ? 0.6 : Number());
        battery->mutable_station()->set_y(plausible ? 0.6 : Number());
        robot->set_recharge_s(plausible ? 60.0 : Number());
      }
    }
    r.set_division(static_cast<v1::FleetDivision>(Below(3)));
    if (Chance(0.3)) r.set_clearance_m(Number());
    return r;
  }
  bool Chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
  int Below(size_t n) {
    return static_cast<int>(std::uniform_int_distribution<size_t>(0, n - 1)(rng_));
  }

 private:
  std::mt19937 rng_;
};

TEST(HostileRequestsTest, EveryReplyIsOkOrAClientErrorAndTheServerSurvives) {
  // Invalid UTF-8 in string fields is sent on purpose; the client library
  // would log an error for each.
  google::protobuf::SetLogHandler(nullptr);
  std::string pattern =
      (std::filesystem::temp_directory_path() / "covplan_hostile_XXXXXX").string();
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const std::string root = pattern;
  {
    ServerProcess server;
    ASSERT_TRUE(server.Start(root + "/maps", {"--metrics_port=-1", "--drain_notice_s=0"}).ok());
    auto channel = grpc::CreateChannel(server.target(), grpc::InsecureChannelCredentials());
    auto stub = v1::CoveragePlanner::NewStub(channel);
    const auto deadline = [] {
      return std::chrono::system_clock::now() + std::chrono::seconds(20);
    };
    std::string good_id;
    {
      grpc::ClientContext context;
      context.set_deadline(deadline());
      v1::PutMapRequest put;
      *put.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1);
      v1::PutMapResponse response;
      ASSERT_TRUE(stub->PutMap(&context, put, &response).ok());
      good_id = response.map_id();
    }
    const int count = EnvInt("COVPLAN_HOSTILE_COUNT", 150);
    Hostile hostile(static_cast<uint32_t>(EnvInt("COVPLAN_HOSTILE_SEED", 1)));
    std::map<std::string, int> outcomes;  // "Method CODE" -> calls
    for (int i = 0; i < count; ++i) {
      grpc::ClientContext context;
      context.set_deadline(deadline());
      grpc::Status status;
      std::string method;
      switch (hostile.Below(8)) {
        case 0: {
          method = "PutMap";
          v1::PutMapRequest r;
          *r.mutable_map() = hostile.Map();
          if (hostile.Chance(0.3)) r.set_name(hostile.Text());
          v1::PutMapResponse out;
          status = stub->PutMap(&context, r, &out);
          break;
        }
        case 1: {
          method = "GetMap";
          v1::GetMapRequest r;
          r.set_map_id(hostile.Chance(0.2) ? good_id : hostile.Text());
          r.set_include_content(hostile.Chance(0.5));
          v1::GetMapResponse out;
          status = stub->GetMap(&context, r, &out);
          break;
        }
        case 2: {
          method = "DeleteMap";
          v1::DeleteMapRequest r;
          r.set_map_id(hostile.Text());
          v1::DeleteMapResponse out;
          status = stub->DeleteMap(&context, r, &out);
          break;
        }
        case 3: {
          method = "ListMaps";
          v1::ListMapsRequest r;
          r.set_page_size(hostile.Chance(0.5) ? hostile.Below(5) - 2
                                              : static_cast<int>(hostile.Number()));
          if (hostile.Chance(0.5)) r.set_page_token(hostile.Text());
          v1::ListMapsResponse out;
          status = stub->ListMaps(&context, r, &out);
          break;
        }
        case 4:
        case 5: {
          method = "Plan";
          v1::PlanResponse out;
          status = stub->Plan(&context, hostile.Plan(good_id), &out);
          break;
        }
        case 6: {
          method = "GetPlan";
          v1::GetPlanRequest r;
          r.set_plan_id(hostile.Text());
          v1::PlanResponse out;
          status = stub->GetPlan(&context, r, &out);
          break;
        }
        default: {
          method = "PlanFleet";
          v1::PlanFleetResponse out;
          status = stub->PlanFleet(&context, hostile.Fleet(good_id), &out);
          break;
        }
      }
      ++outcomes[absl::StrCat(method, " ", CodeName(status.error_code()))];
      EXPECT_NE(status.error_code(), grpc::StatusCode::INTERNAL)
          << method << ": " << status.error_message();
      EXPECT_NE(status.error_code(), grpc::StatusCode::UNKNOWN)
          << method << ": " << status.error_message();
      EXPECT_NE(status.error_code(), grpc::StatusCode::UNAVAILABLE)
          << method << ": " << status.error_message();
      EXPECT_LE(status.error_message().size(), 1100u) << method;
    }
    std::cout << count << " hostile requests (method, gRPC code: calls):\n";
    for (const auto& [key, n] : outcomes) std::cout << "  " << key << ": " << n << "\n";
    absl::StatusOr<int> health = testing::HealthStatus(channel, "");
    EXPECT_TRUE(health.ok() && *health == 1);
    grpc::ClientContext context;
    context.set_deadline(deadline());
    v1::PlanResponse plan;
    EXPECT_TRUE(stub->Plan(&context, testing::PlanRequestFor(good_id, 0.4), &plan).ok());
    EXPECT_EQ(server.Stop(), 0) << server.log().substr(0, 4000);
  }
  std::error_code ec;
  std::filesystem::remove_all(root, ec);
}

}  // namespace
}  // namespace covplan
