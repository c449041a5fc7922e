// `covplan health` against an in-process server: SERVING exits 0; an
// unknown service, a closed port or a draining server exit non-zero.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "client/health_command.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"

namespace covplan {
namespace {

TEST(HealthCommandTest, ExitsZeroOnlyWhileServing) {
  const std::string store =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_health_", ::getpid()))
          .string();
  ServerConfig config;
  config.port = 0;
  config.metrics_port = -1;
  config.store_dir = store;
  config.drain_notice = absl::Seconds(2);
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
  ASSERT_TRUE(server.ok()) << server.status();
  const std::string target = absl::StrCat("127.0.0.1:", (*server)->port());
  EXPECT_EQ(RunHealthCommand({"--server", target}), 0);
  EXPECT_NE(RunHealthCommand({"--server", target, "--service", "no.such.Service"}), 0);
  EXPECT_NE(RunHealthCommand({"--server", "127.0.0.1:1", "--timeout-ms", "300"}), 0);
  EXPECT_NE(RunHealthCommand({"--timeout-ms", "300"}), 0);  // no --server
  // While draining (the notice period) health is NOT_SERVING.
  std::thread drain([&] { (*server)->Drain(absl::Seconds(3)); });
  absl::SleepFor(absl::Milliseconds(500));
  EXPECT_NE(RunHealthCommand({"--server", target, "--timeout-ms", "1000"}), 0);
  drain.join();
  server->reset();
  std::filesystem::remove_all(store);
}

}  // namespace
}  // namespace covplan
