// The `gtsp` CLI subcommand: JSON output, flag forms, exit codes.
#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <string>

#include "client/gtsp_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;
using ::testing::MatchesRegex;

// Square 1-3-5-7 with side 10 (tour cost 40); the other vertices are far away.
constexpr char kSquare[] =
    "NAME : square\nTYPE : GTSP\nDIMENSION : 7\nGTSP_SETS : 4\nEDGE_WEIGHT_TYPE : EUC_2D\n"
    "NODE_COORD_SECTION\n1 0 0\n2 100 100\n3 10 0\n4 200 0\n5 10 10\n6 500 500\n7 0 10\n"
    "GTSP_SET_SECTION\n1 1 2 -1\n2 3 4 -1\n3 5 6 -1\n4 7 -1\nEOF\n";

class GtspCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "gtsp_command_test_" + std::to_string(getpid()) + ".gtsp";
    std::ofstream(path_) << kSquare;
  }
  void TearDown() override { std::remove(path_.c_str()); }

  int Run(const std::vector<std::string>& args, std::string& out, std::string& err) {
    ::testing::internal::CaptureStdout();
    ::testing::internal::CaptureStderr();
    const int rc = RunGtspCommand(args);
    out = ::testing::internal::GetCapturedStdout();
    err = ::testing::internal::GetCapturedStderr();
    return rc;
  }

  std::string path_;
};

TEST_F(GtspCommandTest, PrintsOneJsonObject) {
  std::string out, err;
  ASSERT_EQ(Run({path_, "--seed", "3", "--threads=2"}, out, err), 0) << err;
  EXPECT_THAT(
      out, MatchesRegex("\\{\"instance\":\"square\",\"cost\":40,\"tour\":\\[[1357,]+\\],"
                        "\"time_s\":[0-9.e-]+,\"iterations\":[0-9]+,\"stopped_early\":false\\}\n"));
  EXPECT_TRUE(err.empty()) << err;
}

TEST_F(GtspCommandTest, TimeLimitRunsUntilTheDeadline) {
  std::string out, err;
  ASSERT_EQ(Run({path_, "--time-limit=0.05", "--seed=9"}, out, err), 0) << err;
  EXPECT_THAT(out, HasSubstr("\"cost\":40,"));
  EXPECT_THAT(out, HasSubstr("\"stopped_early\":true"));
}

TEST_F(GtspCommandTest, EverySearchSolvesTheSquare) {
  for (const char* search : {"hybrid", "lns", "memetic"}) {
    std::string out, err;
    ASSERT_EQ(Run({path_, "--time-limit=0.05", "--search", search}, out, err), 0) << err;
    EXPECT_THAT(out, HasSubstr("\"cost\":40,")) << search;
  }
  std::string out, err;
  EXPECT_EQ(Run({path_, "--search", "genetic"}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("--search must be hybrid, lns or memetic, got 'genetic'"));
  EXPECT_TRUE(out.empty());
}

TEST_F(GtspCommandTest, UsageErrorsExitWithTwo) {
  std::string out, err;
  EXPECT_EQ(Run({}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("missing instance FILE"));
  EXPECT_EQ(Run({path_, "--threads", "0"}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("--threads"));
  EXPECT_EQ(Run({path_, "--time-limit"}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("needs a value"));
  EXPECT_EQ(Run({path_, "--colour", "red"}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("unknown flag"));
  EXPECT_EQ(Run({path_, "--time-limit", "-1"}, out, err), 2);
  EXPECT_EQ(Run({"/nonexistent/x.gtsp"}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("cannot open"));
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(Run({"--help"}, out, err), 0);
  EXPECT_THAT(out, HasSubstr("usage: covplan gtsp FILE"));
}

TEST_F(GtspCommandTest, MalformedInstanceExitsWithTwo) {
  std::ofstream(path_)
      << "DIMENSION : 3\nGTSP_SETS : 1\nEDGE_WEIGHT_TYPE : EUC_2D\nNODE_COORD_SECTION\n1 0 0\n";
  std::string out, err;
  EXPECT_EQ(Run({path_}, out, err), 2);
  EXPECT_THAT(err, HasSubstr("line 5"));
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace covplan
