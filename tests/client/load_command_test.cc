// `covplan load --maps`: the requests spread over every map of the list, by
// id (PutMap once) or inline, against an in-process server; each distinct
// map is built once, so the cache sees exactly one miss set per map.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "absl/strings/str_cat.h"
#include "client/load_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

class LoadCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    store_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_load_", ::getpid()))
                 .string();
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.store_dir = store_;
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(store_);
  }

  std::string Run(std::vector<std::string> extra, int* exit_code) {
    std::vector<std::string> args = {"--server", absl::StrCat("127.0.0.1:", server_->port())};
    // Defaults, unless `extra` gives the flag.
    for (const auto& [flag, value] :
         std::vector<std::pair<std::string, std::string>>{{"--concurrency", "2"},
                                                          {"--duration", "60"},
                                                          {"--requests", "8"},
                                                          {"--deadline-ms", "20000"},
                                                          {"--tour", "greedy"}}) {
      if (std::find(extra.begin(), extra.end(), flag) == extra.end())
        args.insert(args.end(), {flag, value});
    }
    args.insert(args.end(), extra.begin(), extra.end());
    ::testing::internal::CaptureStdout();
    *exit_code = RunLoadCommand(args);
    return ::testing::internal::GetCapturedStdout();
  }

  int StoredMaps() const {
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(store_))
      n += e.path().extension() == ".map";
    return n;
  }

  std::string store_;
  std::unique_ptr<CovplanServer> server_;
};

TEST_F(LoadCommandTest, MapsListSpreadsRequestsOverEveryMap) {
  const std::string list = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml,",
                                        COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml");
  int code = -1;
  const std::string json = Run({"--maps", list, "--seed", "5"}, &code);
  EXPECT_EQ(code, 0);
  EXPECT_THAT(json, HasSubstr("\"requests\": 8, \"ok\": 8,"));
  EXPECT_THAT(json, HasSubstr("\"maps\": 2,"));
  // Both maps were registered by PutMap and so built on first use.
  EXPECT_EQ(StoredMaps(), 2);
  // The acknowledged ids are listed, in --maps order.
  EXPECT_THAT(
      json, ::testing::MatchesRegex(".*\"map_ids\": \\[\"[0-9a-f]{64}\", \"[0-9a-f]{64}\"\\]}\n"));
}

TEST_F(LoadCommandTest, InlineMapsNeedNoPutMap) {
  int code = -1;
  const std::string list = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml,",
                                        COVPLAN_SOURCE_DIR, "/maps/sample_yard.geojson");
  const std::string json = Run({"--maps", list, "--inline", "--zipf", "1"}, &code);
  EXPECT_EQ(code, 0);
  EXPECT_THAT(json, HasSubstr("\"requests\": 8, \"ok\": 8,"));
  EXPECT_THAT(json, HasSubstr("\"maps\": 2,"));
  EXPECT_EQ(StoredMaps(), 0);
  EXPECT_THAT(json, ::testing::Not(HasSubstr("map_ids")));
}

// --random-start: every request starts elsewhere, so after the first cold
// search each reply is a warm start (or, for a start drawn twice, a cache
// hit); each reply's plan starts at its drawn pose, which the report's mean
// duration reflects.
TEST_F(LoadCommandTest, RandomStartsWarmStartFromTheRememberedTour) {
  int code = -1;
  const std::string json =
      Run({"--map", absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml"), "--random-start",
           "--concurrency", "1", "--tour", "gtsp", "--seed", "9"},
          &code);
  EXPECT_EQ(code, 0);
  EXPECT_THAT(json, HasSubstr("\"requests\": 8, \"ok\": 8,"));
  EXPECT_THAT(json, HasSubstr("\"random_start\": true"));
  EXPECT_THAT(json, HasSubstr("\"cold\": 1"));
  EXPECT_THAT(json, ::testing::MatchesRegex(".*\"plan_sources\": \\{(\"cache_hit\": [0-9], "
                                            ")?\"cold\": 1, \"warm_start\": [1-7]\\}.*"));
  EXPECT_THAT(json,
              ::testing::ContainsRegex("\"mean_estimated_duration_s\": [1-9][0-9]*\\.[0-9]+"));
}

// --rate paces the requests: 5 at 10 per second take at least 0.4 s (the
// fifth is due then), even though each is answered in milliseconds.
TEST_F(LoadCommandTest, RatePacesTheRequests) {
  int code = -1;
  const std::string json = Run({"--map", absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml"),
                                "--rate", "10", "--requests", "5", "--concurrency", "2"},
                               &code);
  EXPECT_EQ(code, 0);
  EXPECT_THAT(json, HasSubstr("\"requests\": 5, \"ok\": 5,"));
  const size_t at = json.find("\"duration_s\": ");
  ASSERT_NE(at, std::string::npos) << json;
  EXPECT_GE(std::stod(json.substr(at + 14)), 0.4) << json;
  Run({"--map", "a.yaml", "--rate", "0"}, &code);
  EXPECT_NE(code, 0);
}

TEST_F(LoadCommandTest, MapAndMapsAreExclusive) {
  int code = -1;
  Run({"--map", "a.yaml", "--maps", "b.yaml"}, &code);
  EXPECT_NE(code, 0);
}

}  // namespace
}  // namespace covplan
