// Integration tests of issue 13's defects against a real covplan-server
// process, one per defect: checked flags (exit 2), a locked store, deletes
// that change the index only after the file is gone, bounded string fields
// and paged ListMaps, short error messages without server paths, geometry
// validated at PutMap, unguessable plan ids, a full disk reported as such,
// one PutMap repairing a damaged map, a deleted map never planned, FIFOs in
// the store skipped.
#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/synchronization/mutex.h"
#include "absl/synchronization/notification.h"
#include "absl/time/clock.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "png.h"
#include "tests/grid/png_writer.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/server_process.h"
#include "tests/server/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::HealthStatus;
using ::covplan::testing::PillarField;
using ::covplan::testing::RasterMap;
using ::covplan::testing::ServerProcess;
using ::covplan::testing::TwoRooms;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr int kServing = 1, kNotServing = 2;

// Makes `dir` refuse new and removed entries, also for root (the immutable
// attribute); false if this file system or user cannot.
bool SetDirReadOnly(const std::string& dir, bool read_only) {
  if (::geteuid() != 0) return ::chmod(dir.c_str(), read_only ? 0555 : 0755) == 0;
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return false;
  int flags = 0;
  bool ok = ::ioctl(fd, FS_IOC_GETFLAGS, &flags) == 0;
  if (ok) {
    flags = read_only ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
    ok = ::ioctl(fd, FS_IOC_SETFLAGS, &flags) == 0;
  }
  ::close(fd);
  return ok;
}

// An open grpc.health.v1.Health/Watch stream (through the generic stub, the
// request hand-encoded: an empty message watches the server as a whole).
class HealthWatch final : public grpc::ClientBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
 public:
  explicit HealthWatch(const std::shared_ptr<grpc::Channel>& channel) : stub_(channel) {
    stub_.PrepareBidiStreamingCall(&context_, "/grpc.health.v1.Health/Watch", grpc::StubOptions(), this);
    grpc::Slice empty;
    request_ = grpc::ByteBuffer(&empty, 1);
    StartWrite(&request_);
    StartRead(&response_);
    StartCall();
  }
  ~HealthWatch() override {
    context_.TryCancel();
    WaitDone(absl::Seconds(10));
  }
  void OnWriteDone(bool) override { StartWritesDone(); }
  void OnReadDone(bool ok) override {
    if (!ok) return;
    absl::MutexLock lock(&mu_);
    ++reads_;
    StartRead(&response_);
  }
  void OnDone(const grpc::Status&) override {
    absl::MutexLock lock(&mu_);
    done_ = true;
  }
  bool WaitDone(absl::Duration timeout) {
    absl::MutexLock lock(&mu_);
    return mu_.AwaitWithTimeout(absl::Condition(&done_), timeout);
  }
  int reads() {
    absl::MutexLock lock(&mu_);
    return reads_;
  }

 private:
  grpc::GenericStub stub_;
  grpc::ClientContext context_;
  grpc::ByteBuffer request_, response_;
  absl::Mutex mu_;
  bool done_ = false;
  int reads_ = 0;
};

class ServerHardeningTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "covplan_harden_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    store_ = root_ + "/maps";
  }
  void TearDown() override {
    stub_.reset();
    channel_.reset();
    server_.reset();
    SetDirReadOnly(store_, false);
    if (!mount_.empty()) ::umount2(mount_.c_str(), MNT_DETACH);
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }

  void StartServer(const std::vector<std::string>& args = {}) {
    server_ = std::make_unique<ServerProcess>();
    std::vector<std::string> all = {"--metrics_port=-1", "--drain_notice_s=0"};
    all.insert(all.end(), args.begin(), args.end());
    const absl::Status started = server_->Start(store_, all);
    ASSERT_TRUE(started.ok()) << started;
    channel_ = grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials());
    stub_ = v1::CoveragePlanner::NewStub(channel_);
  }

  grpc::Status PutMap(const v1::Map& map, v1::PutMapResponse* response, const std::string& name = "") {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::PutMapRequest request;
    *request.mutable_map() = map;
    request.set_name(name);
    return stub_->PutMap(&context, request, response);
  }
  std::string PutMapOk(const v1::Map& map) {
    v1::PutMapResponse response;
    const grpc::Status status = PutMap(map, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.map_id();
  }
  grpc::Status GetMap(const std::string& map_id) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::GetMapRequest request;
    request.set_map_id(map_id);
    v1::GetMapResponse response;
    return stub_->GetMap(&context, request, &response);
  }
  grpc::Status DeleteMap(const std::string& map_id) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::DeleteMapRequest request;
    request.set_map_id(map_id);
    v1::DeleteMapResponse response;
    return stub_->DeleteMap(&context, request, &response);
  }
  grpc::Status Plan(const std::string& map_id, double tool, v1::PlanResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    v1::PlanRequest request = testing::PlanRequestFor(map_id, tool);
    request.set_time_limit_s(0.3);
    return stub_->Plan(&context, request, response);
  }
  // Waits up to 10 s for `service`'s health to become `want`.
  int AwaitHealth(const std::string& service, int want) {
    int last = -1;
    for (int i = 0; i < 100; ++i) {
      absl::StatusOr<int> status = HealthStatus(channel_, service);
      last = status.ok() ? *status : -1;
      if (last == want) break;
      absl::SleepFor(absl::Milliseconds(100));
    }
    return last;
  }
  // Distinct small maps: TwoRooms with one more pillar per variant.
  static v1::Map Variant(int k) {
    std::vector<std::string> rows = TwoRooms();
    rows[1 + k % 6][1 + k / 6 % 4] = '#';
    return RasterMap(AsciiToPgm(rows, 4), 0.1);
  }

  std::string root_, store_, mount_;
  std::unique_ptr<ServerProcess> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

// Defect 11.
TEST_F(ServerHardeningTest, BadFlagsExitWithCode2AndNameTheFlag) {
  for (const std::string flag : {"--port=70000", "--threads=100000", "--cache_mb=-1", "--plan_ttl_s=-5",
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
  EXPECT_THAT(status.error_message(), HasSubstr("map.raster.yaml is 70016 bytes; the limit is 65536"));
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
    for (const v1::MapInfo& info : response.maps()) EXPECT_TRUE(listed.insert(info.map_id()).second);
    token = response.next_page_token();
    ++pages;
  } while (!token.empty() && pages < 10);
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(listed, ids);
  for (const auto& [size, page_token] : std::vector<std::pair<int, std::string>>{
           {-1, ""}, {2, "not-a-token"}}) {
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
  for (const Case& c : {Case{0.1, 1e308, "origin"}, Case{1e-300, 0, "resolution"},
                        Case{1e300, 0, "resolution"}}) {
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
  for (int i = 0; i < 3; ++i) {
    v1::PlanResponse plan;
    ASSERT_TRUE(Plan(map_id, 0.4, &plan).ok());
    EXPECT_TRUE(std::regex_match(plan.plan_id(), format)) << plan.plan_id();
    ids.push_back(plan.plan_id());
  }
  // Consecutive ids share no long prefix (a salt plus a counter would).
  for (size_t i = 1; i < ids.size(); ++i) {
    EXPECT_NE(ids[i].substr(0, 12), ids[i - 1].substr(0, 12));
  }
}

// Defect 13: a request that is not its protobuf.
TEST_F(ServerHardeningTest, MalformedRequestsAreInvalidArgumentLoggedAndCounted) {
  StartServer({"--metrics_port=0"});
  grpc::GenericStub stub(channel_);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  grpc::Slice junk(std::string("\xff\xff\xff\xff\x0f", 5));
  const grpc::ByteBuffer request(&junk, 1);
  grpc::ByteBuffer response;
  grpc::Status status;
  absl::Notification done;
  stub.UnaryCall(&context, "/covplan.v1.CoveragePlanner/PutMap", grpc::StubOptions(), &request, &response,
                 [&](grpc::Status s) {
                   status = std::move(s);
                   done.Notify();
                 });
  ASSERT_TRUE(done.WaitForNotificationWithTimeout(absl::Seconds(10)));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("covplan.v1.PutMapRequest"));
  EXPECT_THAT(server_->log(), HasSubstr("method=PutMap code=INVALID_ARGUMENT"));
  absl::StatusOr<std::string> metrics = testing::HttpGet(server_->metrics_port(), "/metrics");
  ASSERT_TRUE(metrics.ok()) << metrics.status();
  EXPECT_THAT(*metrics, HasSubstr("covplan_requests_total{code=\"INVALID_ARGUMENT\",method=\"PutMap\"} 1"));
}

// Defect 9: a call admitted behind a long solve that starts with too little
// of its deadline left is refused as overload, not DEADLINE_EXCEEDED.
TEST_F(ServerHardeningTest, TimeLostInTheQueueIsResourceExhaustedNotDeadlineExceeded) {
  StartServer({"--threads=1"});
  const std::string busy_map = PutMapOk(RasterMap(AsciiToPgm(PillarField(120, 90, 200, 3), 4), 0.05));
  const std::string fresh_map = PutMapOk(RasterMap(AsciiToPgm(PillarField(240, 180, 600, 5), 4), 0.025));
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
  // Waits ~1.9 s for the worker, then has ~0.6 s for a map whose artifacts
  // take longer than that to build.
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(2500));
  v1::PlanRequest request = testing::PlanRequestFor(fresh_map, 0.2);
  v1::PlanResponse response;
  const grpc::Status status = stub_->Plan(&context, request, &response);
  busy.join();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("server busy"));
}

// Defect 2: PutMaps whose deadline passed while they waited are not
// decoded, and GetMap does not wait behind decoding.
TEST_F(ServerHardeningTest, QueuedPutMapsPastTheirDeadlineAreDroppedAndReadsDoNotWait) {
  StartServer();
  testing::PngSpec spec{.width = 3000, .height = 3000, .color_type = PNG_COLOR_TYPE_GRAY, .bit_depth = 16};
  spec.samples.assign(static_cast<size_t>(spec.width) * spec.height, 65535);
  const v1::Map big = RasterMap(testing::EncodePng(spec), 0.05);
  const std::string small_id = PutMapOk(Variant(0));
  const absl::Time one_start = absl::Now();
  PutMapOk(big);
  const absl::Duration one = absl::Now() - one_start;  // one decode, uncontended
  // Enough PutMaps that decoding them all would take >= 4 s on the 2 I/O
  // threads; each may wait 0.5 s.
  const int n = std::clamp(static_cast<int>(8 * absl::Seconds(1) / std::max(one, absl::Milliseconds(10))), 8, 60);
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
  while (done.load() < n && absl::Now() < fired + absl::Seconds(60)) absl::SleepFor(absl::Milliseconds(10));
  ASSERT_EQ(done.load(), n);
  // The server stops working on them soon after their deadline: a small
  // PutMap right after is answered at once, not behind the queue.
  const absl::Time after = absl::Now();
  EXPECT_FALSE(PutMapOk(Variant(1)).empty());
  EXPECT_LT(absl::Now() - after, 2 * one + absl::Milliseconds(300))
      << "one decode takes " << absl::FormatDuration(one) << ", " << n << " PutMaps";
  EXPECT_THAT(server_->log(), HasSubstr("not started"));
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

// Defect 7: an open Watch stream, an idle connection and a plan longer than
// the grace; the process still exits within the grace plus a small bound,
// and the plan is answered with its best tour, marked cut short by the drain.
TEST_F(ServerHardeningTest, DrainKeepsItsGraceAndAnswersWithTheBestPlan) {
  StartServer({"--drain_grace_s=1", "--threads=1"});
  const std::string map_id = PutMapOk(RasterMap(AsciiToPgm(PillarField(120, 90, 200, 3), 4), 0.05));
  v1::PlanResponse warm;
  ASSERT_TRUE(Plan(map_id, 0.3, &warm).ok());  // artifacts cached: the next search has a plan at once
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
