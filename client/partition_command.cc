#include "client/partition_command.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "client/args.h"
#include "client/local_engine.h"
#include "client/map_flags.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/partition/push_relabel_partitioner.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan partition --map FILE [--resolution M] [--tool-width M] [--solver NAME]\n"
    "                         [--repeat N] [--free-thresh P] [--occupied-thresh P] [--negate]\n"
    "Computes the minimum rank partition of FILE's coverage grid (as covplan plan reads\n"
    "and grids it; tool width default 0.8 m) with one exact solver, in this process,\n"
    "and prints one JSON object: rows, cols, free_cells, num_ranks, partition_ms (the\n"
    "median of --repeat N timed runs, default 1, each on the ready grid) and grid_ms\n"
    "(building the grid from the map). Solvers:\n"
    "  pushrelabel   s-t minimum cut, push-relabel with global relabelling on the grid\n"
    "                (the planner's default)\n"
    "  matching      maximum bipartite matching, multi-source BFS\n"
    "  matching-hk   the same matching by Hopcroft-Karp\n"
    "  matching-pf   the same matching by Pothen-Fan (PF+)\n"
    "  mincut        s-t minimum cut, Boykov-Kolmogorov with a greedy preflow\n"
    "  mincut-bk     Boykov-Kolmogorov alone\n"
    "  lp            the thesis LP with GLPK (slow on big grids)\n";

absl::StatusOr<std::unique_ptr<RankPartitioner>> SolverNamed(const std::string& name) {
  if (name == "pushrelabel") return std::make_unique<PushRelabelPartitioner>();
  if (name == "matching")
    return std::make_unique<MatchingPartitioner>(MatchingAlgorithm::kMultiSourceBfs);
  if (name == "matching-hk")
    return std::make_unique<MatchingPartitioner>(MatchingAlgorithm::kHopcroftKarp);
  if (name == "matching-pf")
    return std::make_unique<MatchingPartitioner>(MatchingAlgorithm::kPothenFan);
  if (name == "mincut") return std::make_unique<MinCutPartitioner>(true);
  if (name == "mincut-bk") return std::make_unique<MinCutPartitioner>(false);
  if (name == "lp") return std::make_unique<LpPartitioner>();
  return absl::InvalidArgumentError(
      absl::StrCat("--solver must be one of pushrelabel, matching, matching-hk, matching-pf, "
                   "mincut, mincut-bk, lp; got '",
                   name.substr(0, 64), "'"));
}

}  // namespace

absl::StatusOr<std::string> PartitionCommandJson(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(ParsedArgs a, ParseArgs(args,
                                           {"map", "resolution", "tool-width", "solver", "repeat",
                                            "free-thresh", "occupied-thresh"},
                                           {"negate"}));
  if (!a.Get("map")) return absl::InvalidArgumentError("--map FILE is required");
  const std::string map_path = *a.Get("map");
  const std::string solver_name = a.Get("solver").value_or("pushrelabel");
  ASSIGN_OR_RETURN(std::unique_ptr<RankPartitioner> solver, SolverNamed(solver_name));
  ASSIGN_OR_RETURN(std::optional<int64_t> repeat, a.GetInt("repeat"));
  if (repeat && (*repeat < 1 || *repeat > 1000)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--repeat must be in [1, 1000], got %d", *repeat));
  }
  ASSIGN_OR_RETURN(const MapFileOverrides overrides, MapFileOverridesFromFlags(a));
  EngineLimits limits;
  ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(map_path, overrides, limits));
  PlanRequest request;
  ASSIGN_OR_RETURN(std::optional<double> tool, a.GetDouble("tool-width"));
  request.common.robot.tool_width_m = tool.value_or(0.8);
  const LocalEngine local(limits);
  const absl::Time g0 = absl::Now();
  ASSIGN_OR_RETURN(std::shared_ptr<const CoverageArea> area,
                   local.engine().AreaFor(MapSourceFor(map, limits), request));
  const double grid_ms = absl::ToDoubleMilliseconds(absl::Now() - g0);
  const Grid& grid = *area->cover;
  std::vector<double> runs;
  int64_t num_ranks = -1;
  for (int64_t k = 0; k < repeat.value_or(1); ++k) {
    const absl::Time t0 = absl::Now();
    ASSIGN_OR_RETURN(RankPartition p, solver->Partition(grid, StopToken()));
    runs.push_back(absl::ToDoubleMilliseconds(absl::Now() - t0));
    const int64_t n = static_cast<int64_t>(p.ranks.size());
    if (num_ranks >= 0 && n != num_ranks) {
      return absl::InternalError(
          absl::StrFormat("solver %s gave %d ranks, then %d", solver_name, num_ranks, n));
    }
    num_ranks = n;
  }
  std::vector<double> sorted = runs;
  std::sort(sorted.begin(), sorted.end());
  const size_t n = sorted.size();
  const double median = n % 2 == 1 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  return absl::StrFormat(
      "{\"map\": %s, \"solver\": \"%s\", \"tool_width_m\": %g, \"rows\": %d, \"cols\": %d, "
      "\"free_cells\": %d, \"num_ranks\": %d, \"partition_ms\": %.3f, \"partition_ms_runs\": [%s], "
      "\"grid_ms\": %.3f}",
      JsonString(map_path), solver_name, request.common.robot.tool_width_m, grid.rows(),
      grid.cols(), grid.CountFree(), num_ranks, median,
      absl::StrJoin(runs, ", ",
                    [](std::string* out, double v) { absl::StrAppendFormat(out, "%.3f", v); }),
      grid_ms);
}

int RunPartitionCommand(const std::vector<std::string>& args) {
  return RunSubcommand("partition", kUsage, args,
                       [](const std::vector<std::string>& a) -> absl::Status {
                         ASSIGN_OR_RETURN(std::string json, PartitionCommandJson(a));
                         std::printf("%s\n", json.c_str());
                         return absl::OkStatus();
                       });
}

}  // namespace covplan
