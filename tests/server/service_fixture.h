// Test-only fixture of the in-process service tests: a CovplanServer on a
// free port with a fresh store directory, a stub, and PutMap / Plan /
// GetPlan helpers. Subclasses set the knobs (workers, queue, limits,
// metrics) in their constructor.
//
//   class OneWorker : public ServiceTest {
//    protected:
//     OneWorker() { worker_threads_ = 1; }
//   };
//
// Thread-safety: one test thread owns a fixture; the stub may be shared by
// caller threads.
#ifndef COVPLAN_TESTS_SERVER_SERVICE_FIXTURE_H_
#define COVPLAN_TESTS_SERVER_SERVICE_FIXTURE_H_

#include <grpcpp/grpcpp.h>

#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/testing/test_maps.h"

namespace covplan::testing {

inline std::string MakeTempDir() {
  std::string pattern =
      (std::filesystem::temp_directory_path() / "covplan_service_XXXXXX").string();
  const char* dir = mkdtemp(pattern.data());
  return dir == nullptr ? std::string() : std::string(dir);
}

class ServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = MakeTempDir();
    ASSERT_FALSE(dir_.empty());
    ServerConfig config;
    config.port = 0;
    // Stopping the metrics HTTP server takes ~2 s (civetweb's poll loop), so
    // only the metrics test starts it.
    config.metrics_port = with_metrics_ ? 0 : -1;
    config.store_dir = dir_ + "/maps";
    config.service.worker_threads = worker_threads_;
    config.service.max_queue = max_queue_;
    config.service.limits.max_image_bytes = 1 << 20;
    config.service.limits.max_map_pixels = 1'000'000;
    config.service.limits.max_ranks = max_ranks_;
    config.service.limits.dense_transition_bytes = dense_transition_bytes_;
    config.service.max_request_time = max_request_time_;
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    channel_ = grpc::CreateChannel(absl::StrCat("127.0.0.1:", server_->port()),
                                   grpc::InsecureChannelCredentials());
    stub_ = v1::CoveragePlanner::NewStub(channel_);
  }
  void TearDown() override {
    server_.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  grpc::Status PutMap(const v1::Map& map, v1::PutMapResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::PutMapRequest request;
    *request.mutable_map() = map;
    request.set_name("two rooms");
    return stub_->PutMap(&context, request, response);
  }
  grpc::Status Plan(const v1::PlanRequest& request, v1::PlanResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
    return stub_->Plan(&context, request, response);
  }
  grpc::Status GetPlan(const std::string& plan_id, v1::PlanResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::GetPlanRequest get;
    get.set_plan_id(plan_id);
    return stub_->GetPlan(&context, get, response);
  }
  std::string PutTwoRooms() {
    v1::PutMapResponse put;
    const grpc::Status status = PutMap(RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1), &put);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return put.map_id();
  }

  bool with_metrics_ = false;
  int worker_threads_ = 2;
  int max_queue_ = ServiceOptions().max_queue;
  int64_t max_ranks_ = 1000;
  int64_t dense_transition_bytes_ = EngineLimits().dense_transition_bytes;
  absl::Duration max_request_time_ = absl::Seconds(120);
  std::string dir_;
  std::unique_ptr<CovplanServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_SERVICE_FIXTURE_H_
