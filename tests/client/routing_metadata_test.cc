// The client's routing metadata: every RemotePlanner call carries the map it
// is about as `x-covplan-map-id`, the key a map-affine router hashes on. A
// recording CoveragePlanner on loopback answers each call and keeps the
// header it saw.
#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "api/convert.h"
#include "client/remote.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gtest/gtest.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

class RecordingPlanner final : public v1::CoveragePlanner::Service {
 public:
  grpc::Status PutMap(grpc::ServerContext* context, const v1::PutMapRequest*,
                      v1::PutMapResponse* response) override {
    Record(*context);
    response->set_map_id("m");
    return grpc::Status::OK;
  }
  grpc::Status Plan(grpc::ServerContext* context, const v1::PlanRequest*,
                    v1::PlanResponse*) override {
    Record(*context);
    return grpc::Status::OK;
  }
  grpc::Status Replan(grpc::ServerContext* context, const v1::ReplanRequest*,
                      v1::ReplanResponse*) override {
    Record(*context);
    return grpc::Status::OK;
  }

  // The header of each call so far, "<none>" where it was missing; several
  // values of one key would come back joined with ",".
  std::vector<std::string> seen() {
    absl::MutexLock lock(&mu_);
    return seen_;
  }

 private:
  void Record(const grpc::ServerContext& context) {
    const auto& metadata = context.client_metadata();
    std::string value = "<none>";
    for (auto [it, end] = metadata.equal_range("x-covplan-map-id"); it != end; ++it) {
      const std::string v(it->second.data(), it->second.size());
      value = value == "<none>" ? v : value + "," + v;
    }
    absl::MutexLock lock(&mu_);
    seen_.push_back(value);
  }

  absl::Mutex mu_;
  std::vector<std::string> seen_;
};

class RoutingMetadataTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.RegisterService(&service_);
    server_ = builder.BuildAndStart();
    ASSERT_NE(server_, nullptr);
    remote_ = RemotePlanner::Connect("127.0.0.1:" + std::to_string(port));
    map_ = testing::RasterMap(testing::AsciiToPgm(testing::TwoRooms(), 4), 0.1);
  }
  void TearDown() override { server_->Shutdown(); }

  RecordingPlanner service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<RemotePlanner> remote_;
  v1::Map map_;
};

TEST_F(RoutingMetadataTest, PutMapSendsTheContentHash) {
  v1::PutMapRequest put;
  *put.mutable_map() = map_;
  ASSERT_TRUE(remote_->PutMap(put, absl::Seconds(10)).ok());
  ASSERT_EQ(service_.seen().size(), 1u);
  EXPECT_EQ(service_.seen()[0], ComputeMapId(map_));
  EXPECT_EQ(service_.seen()[0].size(), 64u);
}

TEST_F(RoutingMetadataTest, PlanByIdSendsTheIdAndInlineMapItsHash) {
  v1::PlanRequest by_id = testing::PlanRequestFor("0123abcd", 0.4);
  ASSERT_TRUE(remote_->Plan(by_id, absl::Seconds(10)).ok());
  v1::PlanRequest inline_map = by_id;
  *inline_map.mutable_map() = map_;
  ASSERT_TRUE(remote_->Plan(inline_map, std::nullopt).ok());
  const std::vector<std::string> seen = service_.seen();
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0], "0123abcd");
  // The same key PutMap of that map sends, so both land on one replica.
  EXPECT_EQ(seen[1], ComputeMapId(map_));
}

TEST_F(RoutingMetadataTest, ReplanSendsTheInlinePlansMapOrTheGivenId) {
  v1::ReplanRequest inline_plan;
  *inline_plan.mutable_plan()->mutable_request()->mutable_map() = map_;
  ASSERT_TRUE(remote_->Replan(inline_plan, absl::Seconds(10)).ok());
  v1::ReplanRequest by_plan_id;
  by_plan_id.set_plan_id("p-0012ab34-00000003");
  ASSERT_TRUE(remote_->Replan(by_plan_id, absl::Seconds(10), "feedbeef").ok());
  ASSERT_TRUE(remote_->Replan(by_plan_id, absl::Seconds(10)).ok());
  const std::vector<std::string> seen = service_.seen();
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0], ComputeMapId(map_));
  EXPECT_EQ(seen[1], "feedbeef");
  // No map known: no header, so the router balances the call freely.
  EXPECT_EQ(seen[2], "<none>");
}

}  // namespace
}  // namespace covplan
