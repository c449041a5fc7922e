// CovplanServer's --map_store choice: disk is the default, an unknown name
// is refused with a message naming the flag, and postgres without a
// reachable database still starts (it reports UNAVAILABLE until the
// database is there, see pg_map_store_test).
#include <unistd.h>

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

ServerConfig Config(const std::string& store) {
  ServerConfig config;
  config.port = 0;
  config.metrics_port = -1;
  config.store_dir =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_store_choice_", ::getpid()))
          .string();
  config.map_store = store;
  return config;
}

TEST(MapStoreChoiceTest, DiskIsTheDefault) {
  EXPECT_EQ(ServerConfig().map_store, "disk");
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(Config("disk"));
  ASSERT_TRUE(server.ok()) << server.status();
  server->reset();
  std::filesystem::remove_all(Config("disk").store_dir);
}

TEST(MapStoreChoiceTest, UnknownStoreIsRefused) {
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(Config("mongo"));
  EXPECT_EQ(server.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(server.status().message(), HasSubstr("--map_store must be disk or postgres"));
}

TEST(MapStoreChoiceTest, PostgresWithABadConninfoIsRefused) {
  ServerConfig config = Config("postgres");
  config.pg_conninfo = "not a conninfo";
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
  EXPECT_EQ(server.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(server.status().message(), HasSubstr("pg"));
}

}  // namespace
}  // namespace covplan
