// `covplan partition`: one JSON object with the grid's size and the rank
// count of the chosen exact solver, on the grid that planning uses. Every
// solver gives the LP's optimum (an independent formulation); bad flags are
// InvalidArgument naming the flag.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/partition_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/map_io.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

std::string MapPath(const std::string& name) {
  return absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/", name);
}

// The number after "key": in the JSON text (NaN when absent).
double Field(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

// A 30 m x 20 m yard at 0.05 m/px with rectangles and a diagonal wall, as a
// bare PGM (needs --resolution).
std::string WriteYard(const std::string& name) {
  const int w = 600, h = 400;
  std::vector<unsigned char> px(static_cast<size_t>(w) * h, 254);
  auto fill = [&](int x0, int y0, int x1, int y1) {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) px[static_cast<size_t>(y) * w + x] = 0;
    }
  };
  fill(0, 0, w, 4), fill(0, h - 4, w, h), fill(0, 0, 4, h), fill(w - 4, 0, w, h);
  fill(60, 50, 140, 90), fill(300, 200, 330, 380), fill(420, 40, 560, 70), fill(200, 120, 215, 135);
  for (int k = 0; k < 150; ++k) fill(100 + k, 250 + k / 2, 104 + k, 254 + k / 2);
  const std::string path = (std::filesystem::temp_directory_path() /
                            absl::StrCat("covplan_partition_", name, "_", getpid(), ".pgm"))
                               .string();
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << w << " " << h << "\n255\n";
  out.write(reinterpret_cast<const char*>(px.data()), static_cast<std::streamsize>(px.size()));
  return path;
}

TEST(PartitionCommand, EverySolverFindsTheLpOptimumOnThePlanningGrid) {
  const std::string yard = WriteYard("solvers");
  struct Case {
    std::vector<std::string> map_args;
    double tool;
  };
  const std::vector<Case> cases = {
      {{"--map", MapPath("sample_office.yaml")}, 0.8},
      {{"--map", MapPath("sample_office.yaml")}, 0.4},
      {{"--map", MapPath("small_rooms.yaml")}, 0.5},
      {{"--map", yard, "--resolution", "0.05"}, 0.5},
  };
  for (const Case& c : cases) {
    std::vector<std::string> base = c.map_args;
    base.insert(base.end(), {"--tool-width", absl::StrCat(c.tool)});
    std::vector<std::string> lp_args = base;
    lp_args.insert(lp_args.end(), {"--solver", "lp"});
    absl::StatusOr<std::string> lp = PartitionCommandJson(lp_args);
    ASSERT_TRUE(lp.ok()) << lp.status();
    std::printf("%s\n", lp->c_str());
    const double ranks = Field(*lp, "num_ranks");
    EXPECT_GT(ranks, 0);
    for (const char* solver :
         {"pushrelabel", "matching", "matching-hk", "matching-pf", "mincut", "mincut-bk"}) {
      std::vector<std::string> args = base;
      args.insert(args.end(), {"--solver", solver, "--repeat", "2"});
      absl::StatusOr<std::string> json = PartitionCommandJson(args);
      ASSERT_TRUE(json.ok()) << solver << ": " << json.status();
      EXPECT_EQ(Field(*json, "num_ranks"), ranks) << solver << " " << c.map_args[1];
      EXPECT_EQ(Field(*json, "free_cells"), Field(*lp, "free_cells"));
      EXPECT_GE(Field(*json, "partition_ms"), 0.0);
      EXPECT_THAT(*json, HasSubstr(absl::StrCat("\"solver\": \"", solver, "\"")));
      EXPECT_THAT(*json, HasSubstr("\"partition_ms_runs\": ["));
    }
  }
  std::filesystem::remove(yard);
}

TEST(PartitionCommand, TheGridIsTheOnePlanningUses) {
  absl::StatusOr<std::string> json =
      PartitionCommandJson({"--map", MapPath("sample_office.yaml"), "--tool-width", "0.8"});
  ASSERT_TRUE(json.ok()) << json.status();
  absl::StatusOr<OccupancyMap> map = LoadMapFile(MapPath("sample_office.yaml"), MapLoadOptions());
  ASSERT_TRUE(map.ok());
  PlanOptions o;
  o.robot.tool_width_m = 0.8;
  o.time_limit_s = 0.2;
  absl::StatusOr<EngineResult> plan = PlanCoverageWithArea(*map, o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(Field(*json, "rows"), plan->area->cover->rows());
  EXPECT_EQ(Field(*json, "cols"), plan->area->cover->cols());
  EXPECT_EQ(Field(*json, "free_cells"), plan->area->cover->CountFree());
  EXPECT_EQ(Field(*json, "num_ranks"), plan->plan.stats.num_ranks);
}

TEST(PartitionCommand, BadFlagsAreInvalidArgumentNamingThem) {
  const std::string office = MapPath("sample_office.yaml");
  const std::string yard = WriteYard("flags");
  struct Case {
    std::vector<std::string> args;
    const char* message;
  };
  const std::vector<Case> cases = {
      {{}, "--map"},
      {{"--map", office, "--solver", "simplex"}, "--solver must be one of"},
      {{"--map", office, "--repeat", "0"}, "--repeat"},
      {{"--map", office, "--tool-width", "-1"}, "tool_width"},
      {{"--map", yard}, "--resolution"},
      {{"--map", office, "--bogus", "1"}, "bogus"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<std::string> json = PartitionCommandJson(c.args);
    EXPECT_EQ(json.status().code(), absl::StatusCode::kInvalidArgument)
        << c.message << ": " << json.status();
    EXPECT_THAT(std::string(json.status().message()), HasSubstr(c.message));
  }
  std::filesystem::remove(yard);
}

}  // namespace
}  // namespace covplan
