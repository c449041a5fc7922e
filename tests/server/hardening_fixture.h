// Test-only fixture of the issue-13 hardening suites against a real
// covplan-server process: start/stop, map calls, health polling, small
// distinct maps, a read-only store directory, an open health Watch stream.
//
//   class MyTest : public ServerHardeningTest {};
//   TEST_F(MyTest, X) { StartServer({"--threads=1"}); PutMapOk(Variant(0)); }
//
// Thread-safety: one test thread owns a fixture; HealthWatch is internally
// synchronised.
#ifndef COVPLAN_TESTS_SERVER_HARDENING_FIXTURE_H_
#define COVPLAN_TESTS_SERVER_HARDENING_FIXTURE_H_

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "absl/time/clock.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gtest/gtest.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/server_process.h"
#include "tests/testing/test_maps.h"

namespace covplan::testing {

constexpr int kServing = 1, kNotServing = 2;

// Makes `dir` refuse new and removed entries, also for root (the immutable
// attribute); false if this file system or user cannot.
inline bool SetDirReadOnly(const std::string& dir, bool read_only) {
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
    stub_.PrepareBidiStreamingCall(&context_, "/grpc.health.v1.Health/Watch", grpc::StubOptions(),
                                   this);
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
    std::string pattern =
        (std::filesystem::temp_directory_path() / "covplan_harden_XXXXXX").string();
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
    std::vector<std::string> all = testing::QuietServerFlags();
    all.insert(all.end(), args.begin(), args.end());
    const absl::Status started = server_->Start(store_, all);
    ASSERT_TRUE(started.ok()) << started;
    channel_ = grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials());
    stub_ = v1::CoveragePlanner::NewStub(channel_);
  }

  grpc::Status PutMap(const v1::Map& map, v1::PutMapResponse* response,
                      const std::string& name = "") {
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
      absl::StatusOr<int> status = testing::HealthStatus(channel_, service);
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

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_HARDENING_FIXTURE_H_
