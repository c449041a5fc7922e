// Integration tests of hardening defects against a real covplan-server
// process, one per defect: checked flags (exit 2), a locked store, deletes
// that change the index only after the file is gone, bounded string fields
// and paged ListMaps, short error messages without server paths, geometry
// validated at PutMap, unguessable plan ids, a full disk reported as such,
// one PutMap repairing a damaged map, a deleted map never planned, FIFOs in
// the store skipped. (Load, overload and drain: server_load_drain_test.cc.)
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/synchronization/notification.h"
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

// Defect 11.
TEST_F(ServerHardeningTest, BadFlagsExitWithCode2AndNameTheFlag) {
  for (const std::string flag :
       {"--port=70000", "--threads=100000", "--cache_mb=-1", "--plan_ttl_s=-5",
        "--drain_grace_s=-1", "--max_retained_plans=0"}) {
    ServerProcess server;
    const absl::Status started = server.Start(store_, {flag});
    EXPECT_FALSE(started.ok()) << flag;
    EXPECT_EQ(server.start_exit_status(), 2) << flag << "\n" << server.log();
    EXPECT_THAT(server.log(), HasSubstr(flag)) << flag;
  }
}

// Defect 5.
TEST_F(ServerHardeningTest, SecondServerOnTheSameStoreExitsWithAClearMessage) {
  StartServer();
  ServerProcess second;
  EXPECT_FALSE(second.Start(store_, {"--metrics_port=-1"}).ok());
  EXPECT_EQ(second.start_exit_status(), 1);
  EXPECT_THAT(second.log(), HasSubstr("in use by another covplan-server"));
  // The first one still serves.
  EXPECT_FALSE(PutMapOk(Variant(0)).empty());
}

// Defect 4 (and 8: no server paths in errors).
TEST_F(ServerHardeningTest, FailedDeleteKeepsTheMap) {
  StartServer();
  const std::string map_id = PutMapOk(Variant(0));
  if (!SetDirReadOnly(store_, true)) GTEST_SKIP() << "cannot make the store read-only here";
  const grpc::Status deleted = DeleteMap(map_id);
  SetDirReadOnly(store_, false);
  EXPECT_FALSE(deleted.ok());
  EXPECT_EQ(deleted.error_code(), grpc::StatusCode::UNAVAILABLE) << deleted.error_message();
  EXPECT_THAT(deleted.error_message(), HasSubstr("not writable"));
  EXPECT_THAT(deleted.error_message(), Not(HasSubstr(root_)));
  EXPECT_TRUE(GetMap(map_id).ok());
  v1::PlanResponse plan;
  EXPECT_TRUE(Plan(map_id, 0.4, &plan).ok());
  // Writable again: the delete works and is final.
  EXPECT_TRUE(DeleteMap(map_id).ok());
  EXPECT_EQ(GetMap(map_id).error_code(), grpc::StatusCode::NOT_FOUND);
}

// Defect 3.
TEST_F(ServerHardeningTest, OverlongStringsAreRejectedNamingFieldAndLimit) {
  StartServer();
  v1::PutMapResponse put;
  grpc::Status status = PutMap(Variant(0), &put, std::string(300, 'n'));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("name is 300 bytes; the limit is 256 bytes"));
  v1::Map big_yaml = Variant(0);
  big_yaml.mutable_raster()->set_yaml("resolution: 0.1\n" + std::string(70000, '#'));
  status = PutMap(big_yaml, &put);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(),
              HasSubstr("map.raster.yaml is 70016 bytes; the limit is 65536"));
  {
    grpc::ClientContext context;
    v1::PlanRequest request = testing::PlanRequestFor(std::string(5000, 'a'), 0.4);
    v1::PlanResponse response;
    status = stub_->Plan(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("map_id is 5000 bytes"));
  }
  // The map with a legal name is listed with it.
  EXPECT_TRUE(PutMap(Variant(0), &put, std::string(256, 'n')).ok());
}

// Defect 3: ListMaps pages.
TEST_F(ServerHardeningTest, ListMapsIsPaged) {
  StartServer();
  std::set<std::string> ids;
  for (int k = 0; k < 5; ++k) ids.insert(PutMapOk(Variant(k)));
  ASSERT_EQ(ids.size(), 5u);
  std::set<std::string> listed;
  std::string token;
  int pages = 0;
  do {
    grpc::ClientContext context;
    v1::ListMapsRequest request;
    request.set_page_size(2);
    request.set_page_token(token);
    v1::ListMapsResponse response;
    ASSERT_TRUE(stub_->ListMaps(&context, request, &response).ok());
    EXPECT_LE(response.maps_size(), 2);
    for (const v1::MapInfo& info : response.maps())
      EXPECT_TRUE(listed.insert(info.map_id()).second);
    token = response.next_page_token();
    ++pages;
  } while (!token.empty() && pages < 10);
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(listed, ids);
  for (const auto& [size, page_token] :
       std::vector<std::pair<int, std::string>>{{-1, ""}, {2, "not-a-token"}}) {
    grpc::ClientContext context;
    v1::ListMapsRequest request;
    request.set_page_size(size);
    request.set_page_token(page_token);
    v1::ListMapsResponse response;
    EXPECT_EQ(stub_->ListMaps(&context, request, &response).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
  }
}

// Defect 8.
TEST_F(ServerHardeningTest, ErrorsQuoteOnlyAShortPrefixAndLogLinesAreBounded) {
  StartServer();
  {
    grpc::ClientContext context;
    v1::GetPlanRequest request;
    request.set_plan_id(std::string(1 << 20, 'p'));
    v1::PlanResponse response;
    const grpc::Status status = stub_->GetPlan(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_LT(status.error_message().size(), 200u) << status.error_message().substr(0, 300);
  }
  {
    grpc::ClientContext context;
    v1::GetPlanRequest request;
    request.set_plan_id(std::string(1000, 'q'));  // under the bound: NOT_FOUND, quoted short
    v1::PlanResponse response;
    const grpc::Status status = stub_->GetPlan(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_LT(status.error_message().size(), 200u);
  }
  v1::Map map = Variant(0);
  map.mutable_raster()->clear_resolution();
  map.mutable_raster()->set_yaml("resolution: " + std::string(60000, '9') + "x\n");
  v1::PutMapResponse put;
  const grpc::Status status = PutMap(map, &put);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_LT(status.error_message().size(), 1100u);
  for (const absl::string_view line : absl::StrSplit(server_->log(), '\n')) {
    EXPECT_LT(line.size(), 4096u) << line.substr(0, 200);
  }
}

// Defect 12.
TEST_F(ServerHardeningTest, PutMapRejectsGeometryThatCannotBePlanned) {
  StartServer();
  struct Case {
    double resolution, origin_x;
    const char* expect;
  };
  for (const Case& c :
       {Case{0.1, 1e308, "origin"}, Case{1e-300, 0, "resolution"}, Case{1e300, 0, "resolution"}}) {
    v1::Map map = Variant(0);
    map.mutable_raster()->set_resolution(c.resolution);
    map.mutable_raster()->set_origin_x_m(c.origin_x);
    v1::PutMapResponse put;
    const grpc::Status status = PutMap(map, &put);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.expect;
    EXPECT_THAT(status.error_message(), HasSubstr(c.expect));
    EXPECT_THAT(status.error_message(), Not(HasSubstr("start")));
  }
}

// Defect 13.
TEST_F(ServerHardeningTest, PlanIdsAreRandom128BitValues) {
  StartServer();
  const std::string map_id = PutMapOk(Variant(0));
  const std::regex format("p-[0-9a-f]{32}");
  std::vector<std::string> ids;
  // Three different requests (an identical one would get the remembered
  // plan, under its id).
  for (int i = 0; i < 3; ++i) {
    v1::PlanResponse plan;
    ASSERT_TRUE(Plan(map_id, 0.4 + 0.1 * i, &plan).ok());
    EXPECT_TRUE(std::regex_match(plan.plan_id(), format)) << plan.plan_id();
    ids.push_back(plan.plan_id());
  }
  // Consecutive ids share no long prefix (a salt plus a counter would).
  for (size_t i = 1; i < ids.size(); ++i) {
    EXPECT_NE(ids[i].substr(0, 12), ids[i - 1].substr(0, 12));
  }
}

// Defect 14.
TEST_F(ServerHardeningTest, FullDiskIsResourceExhaustedAndReportedInHealthAndMetrics) {
  mount_ = root_ + "/small";
  std::filesystem::create_directories(mount_);
  if (::mount("tmpfs", mount_.c_str(), "tmpfs", 0, "size=256k") != 0) {
    mount_.clear();
    GTEST_SKIP() << "cannot mount a small tmpfs here";
  }
  store_ = mount_ + "/maps";
  StartServer({"--metrics_port=0"});
  EXPECT_EQ(AwaitHealth("covplan.v1.MapStore", kServing), kServing);
  {  // Fill the disk.
    std::ofstream filler(mount_ + "/filler", std::ios::binary);
    const std::string block(4096, 'x');
    for (int i = 0; i < 200 && filler.write(block.data(), block.size()); ++i) {
    }
  }
  v1::PutMapResponse put;
  const grpc::Status status = PutMap(Variant(1), &put);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("store is full"));
  EXPECT_THAT(status.error_message(), Not(HasSubstr(mount_)));
  EXPECT_EQ(AwaitHealth("covplan.v1.MapStore", kNotServing), kNotServing);
  EXPECT_EQ(AwaitHealth("", kServing), kServing);  // plans still work
  absl::StatusOr<std::string> metrics = testing::HttpGet(server_->metrics_port(), "/metrics");
  ASSERT_TRUE(metrics.ok()) << metrics.status();
  EXPECT_THAT(*metrics, HasSubstr("covplan_store_writable 0"));
  std::filesystem::remove(mount_ + "/filler");
  EXPECT_EQ(AwaitHealth("covplan.v1.MapStore", kServing), kServing);
  EXPECT_TRUE(PutMap(Variant(1), &put).ok());
}

// Defect 6.
TEST_F(ServerHardeningTest, OnePutMapRepairsAMapDamagedAtRuntime) {
  StartServer();
  const v1::Map map = Variant(0);
  const std::string map_id = PutMapOk(map);
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(map_id, 0.4, &plan).ok());  // its artifacts are cached now
  {
    std::fstream f(store_ + "/" + map_id + ".map", std::ios::in | std::ios::out | std::ios::binary);
    ASSERT_TRUE(f.good());
    f.seekp(-20, std::ios::end);
    f.put('\x01');
  }
  EXPECT_EQ(GetMap(map_id).error_code(), grpc::StatusCode::DATA_LOSS);
  // Reported damaged: not planned from the cache.
  EXPECT_EQ(Plan(map_id, 0.4, &plan).error_code(), grpc::StatusCode::DATA_LOSS);
  v1::PutMapResponse put;
  const grpc::Status repaired = PutMap(map, &put);
  EXPECT_TRUE(repaired.ok()) << repaired.error_message();
  EXPECT_TRUE(put.created());
  EXPECT_TRUE(GetMap(map_id).ok());
  EXPECT_TRUE(Plan(map_id, 0.4, &plan).ok());
}

// Defect 6, the other way round: damaged on disk, then PutMap before anyone
// read it (the index still says intact).
TEST_F(ServerHardeningTest, PutMapOfAnIntactlyIndexedButDamagedFileRewritesIt) {
  StartServer();
  const v1::Map map = Variant(0);
  const std::string map_id = PutMapOk(map);
  std::filesystem::resize_file(store_ + "/" + map_id + ".map", 30);
  v1::PutMapResponse put;
  const grpc::Status status = PutMap(map, &put);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(put.created());
  EXPECT_TRUE(GetMap(map_id).ok());
}

// Defect 1: a Plan building the map's artifacts while DeleteMap runs.
TEST_F(ServerHardeningTest, ADeletedMapIsNeverPlannedAgain) {
  StartServer();
  const std::string map_id =
      PutMapOk(RasterMap(AsciiToPgm(PillarField(160, 120, 150, 7), 4), 0.025));
  std::thread first([&] {
    v1::PlanResponse plan;
    Plan(map_id, 0.3, &plan);  // may finish or not; the delete decides what follows
  });
  absl::SleepFor(absl::Milliseconds(200));
  EXPECT_TRUE(DeleteMap(map_id).ok());
  first.join();
  v1::PlanResponse plan;
  EXPECT_EQ(Plan(map_id, 0.3, &plan).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(GetMap(map_id).error_code(), grpc::StatusCode::NOT_FOUND);
}

// Defect 10: only regular files are opened.
TEST_F(ServerHardeningTest, AFifoInTheStoreDoesNotHangStartup) {
  std::filesystem::create_directories(store_);
  const std::string fifo = store_ + "/" + std::string(64, 'a') + ".map";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const absl::Time start = absl::Now();
  StartServer();
  EXPECT_LT(absl::Now() - start, absl::Seconds(5));
  EXPECT_EQ(GetMap(std::string(64, 'a')).error_code(), grpc::StatusCode::NOT_FOUND);
}

}  // namespace
}  // namespace covplan
