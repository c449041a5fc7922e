#include "client/compare_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "client/args.h"
#include "client/local_engine.h"
#include "client/map_flags.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/common/status_macros.h"
#include "planner/fleet/fleet_planner.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan compare --map FILE [--algorithms oarp,stc,...] [--tool-width M]\n"
    "                       [--json out.json] [--markdown] [--no-header] [--name NAME]\n"
    "                       [--resolution M] [--free-thresh P] [--occupied-thresh P] [--negate]\n"
    "                       [--time-limit S] [--seed N] [--robots K]\n"
    "Plans FILE (as covplan plan reads it) with each planner, in this process, with\n"
    "its default options, and prints one table: turns, path length, estimated\n"
    "duration, covered free-area ratio, redundant cells (cells to cover the path\n"
    "enters more than once) and planning time. Default: every registered planner.\n"
    "--markdown prints a markdown table (with a map column named NAME, default the\n"
    "file name; --no-header leaves out the header rows). --json writes the rows.\n"
    "--robots K plans each planner as a K-robot fleet (robots spread by the planner,\n"
    "--time-limit per fleet) with the makespan division and with equal areas, and\n"
    "prints the makespan, its lower bound, the gap and the equal-area makespan.\n";

std::string TerminationText(const Termination& t) {
  if (!t.limit_reached()) return "converged";
  return absl::StrCat("limit: ", TerminationLimitName(t.limit));
}

// Prints `table`, or with --markdown the markdown of `markdown(name,
// header)`, and writes `json` to --json when given.
template <typename Markdown>
absl::Status Print(const ParsedArgs& a, const std::string& map_path, const std::string& table,
                   Markdown markdown, const std::string& json) {
  if (a.Has("markdown")) {
    std::string name = a.Get("name").value_or(map_path.substr(map_path.find_last_of('/') + 1));
    std::fputs(markdown(name, !a.Has("no-header")).c_str(), stdout);
  } else {
    std::fputs(table.c_str(), stdout);
  }
  if (auto path = a.Get("json")) RETURN_IF_ERROR(WriteTextFile(*path, json));
  return absl::OkStatus();
}

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(ParsedArgs a, ParseArgs(args,
                                           {"map", "algorithms", "tool-width", "json", "resolution",
                                            "free-thresh", "occupied-thresh", "time-limit", "seed",
                                            "name", "robots"},
                                           {"markdown", "no-header", "negate"}));
  if (!a.Get("map")) return absl::InvalidArgumentError("--map FILE is required");
  const std::string map_path = *a.Get("map");
  ASSIGN_OR_RETURN(const MapFileOverrides overrides, MapFileOverridesFromFlags(a));
  EngineLimits limits;
  ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(map_path, overrides, limits));
  const PlannerRegistry registry = BuiltinPlanners();
  std::vector<std::string> planners = registry.Names();
  if (auto list = a.Get("algorithms")) {
    std::vector<std::string> named = absl::StrSplit(*list, ',', absl::SkipWhitespace());
    planners = std::move(named);
    if (planners.empty()) return absl::InvalidArgumentError("--algorithms is empty");
  }
  PlanRequest request;
  ASSIGN_OR_RETURN(std::optional<double> tool, a.GetDouble("tool-width"));
  request.common.robot.tool_width_m = tool.value_or(0.8);
  ASSIGN_OR_RETURN(std::optional<double> limit, a.GetDouble("time-limit"));
  if (limit) request.common.time_limit_s = *limit;
  ASSIGN_OR_RETURN(std::optional<int64_t> seed, a.GetInt("seed"));
  if (seed) request.common.seed = static_cast<uint64_t>(*seed);
  ASSIGN_OR_RETURN(std::optional<int64_t> robots, a.GetInt("robots"));
  if (robots) {
    if (*robots < 1 || *robots > FleetRequest::kMaxRobots) {
      return absl::InvalidArgumentError(absl::StrFormat("--robots must be in [1, %d], got %d",
                                                        FleetRequest::kMaxRobots, *robots));
    }
    ASSIGN_OR_RETURN(std::vector<FleetComparisonRow> rows,
                     CompareFleets(registry, MapSourceFor(map, limits), planners, request,
                                   static_cast<int>(*robots), limits));
    return Print(
        a, map_path, FleetComparisonTable(rows),
        [&](const std::string& name, bool header) {
          return FleetComparisonMarkdown(rows, name, header);
        },
        FleetComparisonJson(rows, map_path, request.common.robot.tool_width_m));
  }
  ASSIGN_OR_RETURN(std::vector<ComparisonRow> rows,
                   ComparePlanners(registry, MapSourceFor(map, limits), planners, request, limits));
  return Print(
      a, map_path, ComparisonTable(rows),
      [&](const std::string& name, bool header) { return ComparisonMarkdown(rows, name, header); },
      ComparisonJson(rows, map_path, request.common.robot.tool_width_m));
}

}  // namespace

int64_t CountRedundantCells(const CoverageArea& area, const std::vector<Waypoint>& path) {
  const Grid& grid = *area.drive;
  const Grid& cover = *area.cover;
  std::vector<uint16_t> entries(grid.size(), 0);
  if (path.empty()) return 0;
  auto enter = [&](CellIndex c) {
    if (grid.InBounds(c.row, c.col)) {
      uint16_t& e = entries[grid.Index(c.row, c.col)];
      if (e < 2) ++e;
    }
  };
  CellIndex prev = grid.CellAt({path[0].x, path[0].y});
  enter(prev);
  for (size_t i = 1; i < path.size(); ++i) {
    const Waypoint& a = path[i - 1];
    const Waypoint& b = path[i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.01 * grid.cell_size()))));
    for (int k = 1; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const CellIndex c = grid.CellAt({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
      if (c != prev) enter(c);
      prev = c;
    }
  }
  int64_t redundant = 0;
  for (int64_t i = 0; i < grid.size(); ++i) redundant += entries[i] > 1 && cover.free_flags()[i];
  return redundant;
}

absl::StatusOr<std::vector<ComparisonRow>> ComparePlanners(const PlannerRegistry& registry,
                                                           const MapSource& source,
                                                           const std::vector<std::string>& planners,
                                                           const PlanRequest& request,
                                                           const EngineLimits& limits) {
  for (const std::string& name : planners) {
    if (registry.Find(name) == nullptr) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "unknown algorithm '%s'; registered: %s", name, absl::StrJoin(registry.Names(), ", ")));
    }
  }
  std::vector<ComparisonRow> rows;
  for (const std::string& name : planners) {
    const LocalEngine local(limits, registry);  // each planner pays for its own grid and artifacts
    PlanRequest r = request;
    r.planner = name;
    r.options = nullptr;
    const absl::Time t0 = absl::Now();
    absl::StatusOr<EngineResult> result = local.engine().Plan(source, r);
    const double ms = absl::ToDoubleMilliseconds(absl::Now() - t0);
    if (!result.ok()) {
      return absl::Status(result.status().code(),
                          absl::StrCat(name, ": ", result.status().message()));
    }
    const PlanStats& s = result->plan.stats;
    ComparisonRow row;
    row.planner = name;
    row.turns = s.num_turns;
    row.length_m = s.coverage_length_m + s.transition_length_m;
    row.duration_s = s.estimated_duration_s;
    row.cells_to_cover = s.free_cells;
    row.covered_cells = s.covered_cells;
    // The area's ratio assumes every cell to cover is swept; scale it by the
    // share actually swept (equal for planners that cover everything).
    row.covered_free_area_ratio =
        s.free_cells > 0 ? s.covered_free_area_ratio *
                               std::min<double>(1.0, static_cast<double>(s.covered_cells) /
                                                         static_cast<double>(s.free_cells))
                         : 0.0;
    row.redundant_cells = CountRedundantCells(*result->area, result->plan.path);
    row.planning_ms = ms;
    row.termination = TerminationText(result->plan.termination);
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string ComparisonTable(const std::vector<ComparisonRow>& rows) {
  std::string out =
      absl::StrFormat("%-14s %7s %11s %12s %9s %16s %12s  %s\n", "planner", "turns", "length_m",
                      "duration_s", "covered", "redundant_cells", "planning_ms", "search");
  for (const ComparisonRow& r : rows) {
    out += absl::StrFormat(
        "%-14s %7d %11.1f %12.1f %8.1f%% %9d (%4.1f%%) %12.1f  %s\n", r.planner, r.turns,
        r.length_m, r.duration_s, 100.0 * r.covered_free_area_ratio, r.redundant_cells,
        r.cells_to_cover > 0 ? 100.0 * r.redundant_cells / r.cells_to_cover : 0.0, r.planning_ms,
        r.termination);
  }
  return out;
}

std::string ComparisonMarkdown(const std::vector<ComparisonRow>& rows, const std::string& map_name,
                               bool header) {
  std::string out;
  const std::string lead = map_name.empty() ? "" : "| map ";
  if (header) {
    out += lead +
           "| planner | turns | length (m) | duration (s) | covered free area | redundant cells | "
           "planning (ms) |\n";
    out += std::string(map_name.empty() ? "" : "|---") + "|---|---:|---:|---:|---:|---:|---:|\n";
  }
  for (const ComparisonRow& r : rows) {
    if (!map_name.empty()) out += absl::StrCat("| ", map_name, " ");
    out += absl::StrFormat(
        "| %s | %d | %.1f | %.1f | %.1f %% | %d (%.1f %%) | %.1f |\n", r.planner, r.turns,
        r.length_m, r.duration_s, 100.0 * r.covered_free_area_ratio, r.redundant_cells,
        r.cells_to_cover > 0 ? 100.0 * r.redundant_cells / r.cells_to_cover : 0.0, r.planning_ms);
  }
  return out;
}

std::string ComparisonJson(const std::vector<ComparisonRow>& rows, const std::string& map_path,
                           double tool_width_m) {
  auto quote = [](const std::string& s) {
    std::string q = "\"";
    for (char c : s) {
      if (c == '"' || c == '\\') q += '\\';
      if (static_cast<unsigned char>(c) < 0x20) {
        q += absl::StrFormat("\\u%04x", c);
        continue;
      }
      q += c;
    }
    return q + "\"";
  };
  std::vector<std::string> items;
  for (const ComparisonRow& r : rows) {
    items.push_back(absl::StrFormat(
        "    {\"planner\": %s, \"turns\": %d, \"length_m\": %.6g, \"duration_s\": %.6g, "
        "\"covered_free_area_ratio\": %.6g, \"cells_to_cover\": %d, \"covered_cells\": %d, "
        "\"redundant_cells\": %d, \"planning_ms\": %.6g, \"termination\": %s}",
        quote(r.planner), r.turns, r.length_m, r.duration_s, r.covered_free_area_ratio,
        r.cells_to_cover, r.covered_cells, r.redundant_cells, r.planning_ms, quote(r.termination)));
  }
  return absl::StrFormat(
      "{\n  \"map\": %s,\n  \"tool_width_m\": %.6g,\n  \"planners\": [\n%s\n  ]\n}\n",
      quote(map_path), tool_width_m, absl::StrJoin(items, ",\n"));
}

absl::StatusOr<std::vector<FleetComparisonRow>> CompareFleets(
    const PlannerRegistry& registry, const MapSource& source,
    const std::vector<std::string>& planners, const PlanRequest& request, int robots,
    const EngineLimits& limits) {
  for (const std::string& name : planners) {
    if (registry.Find(name) == nullptr) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "unknown algorithm '%s'; registered: %s", name, absl::StrJoin(registry.Names(), ", ")));
    }
  }
  FleetRequest fleet;
  for (int i = 0; i < robots; ++i) {
    FleetRobot robot;
    robot.id = absl::StrCat("r", i + 1);
    robot.robot = request.common.robot;
    fleet.robots.push_back(std::move(robot));
  }
  std::vector<FleetComparisonRow> rows;
  for (const std::string& name : planners) {
    const LocalEngine local(limits, registry);
    fleet.base = request;
    fleet.base.planner = name;
    fleet.base.options = nullptr;
    FleetPlan plans[2];
    for (FleetDivision d : {FleetDivision::kMakespan, FleetDivision::kEqualArea}) {
      fleet.division = d;
      absl::StatusOr<FleetPlan> plan = PlanFleet(local.engine(), source, fleet);
      if (!plan.ok()) {
        return absl::Status(plan.status().code(), absl::StrCat(name, " (", FleetDivisionName(d),
                                                               "): ", plan.status().message()));
      }
      plans[static_cast<int>(d)] = *std::move(plan);
    }
    const FleetPlan& m = plans[0];
    const FleetPlan& e = plans[1];
    FleetComparisonRow row;
    row.planner = name;
    row.robots = robots;
    row.makespan_s = m.makespan_s;
    row.lower_bound_s = m.lower_bound_s;
    row.gap = m.gap;
    row.equal_area_makespan_s = e.makespan_s;
    row.equal_area_gap = e.gap;
    row.cells_to_cover = m.cover_cells;
    row.covered_cells = m.covered_cells;
    row.planning_ms = m.planning_ms + e.planning_ms;
    row.termination = TerminationText(m.termination);
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string FleetComparisonTable(const std::vector<FleetComparisonRow>& rows) {
  std::string out = absl::StrFormat("%-14s %6s %11s %14s %8s %13s %9s %12s  %s\n", "planner",
                                    "robots", "makespan_s", "lower_bound_s", "gap", "equal_area_s",
                                    "covered", "planning_ms", "search");
  for (const FleetComparisonRow& r : rows) {
    out += absl::StrFormat("%-14s %6d %11.1f %14.1f %7.1f%% %13.1f %8.1f%% %12.1f  %s\n", r.planner,
                           r.robots, r.makespan_s, r.lower_bound_s, 100.0 * r.gap,
                           r.equal_area_makespan_s,
                           r.cells_to_cover > 0 ? 100.0 * r.covered_cells / r.cells_to_cover : 0.0,
                           r.planning_ms, r.termination);
  }
  return out;
}

std::string FleetComparisonMarkdown(const std::vector<FleetComparisonRow>& rows,
                                    const std::string& map_name, bool header) {
  std::string out;
  const std::string lead = map_name.empty() ? "" : "| map ";
  if (header) {
    out += lead +
           "| planner | robots | makespan (s) | lower bound (s) | gap | equal-area makespan (s) | "
           "planning (ms) |\n";
    out += std::string(map_name.empty() ? "" : "|---") + "|---|---:|---:|---:|---:|---:|---:|\n";
  }
  for (const FleetComparisonRow& r : rows) {
    if (!map_name.empty()) out += absl::StrCat("| ", map_name, " ");
    out += absl::StrFormat("| %s | %d | %.1f | %.1f | %.1f %% | %.1f | %.1f |\n", r.planner,
                           r.robots, r.makespan_s, r.lower_bound_s, 100.0 * r.gap,
                           r.equal_area_makespan_s, r.planning_ms);
  }
  return out;
}

std::string FleetComparisonJson(const std::vector<FleetComparisonRow>& rows,
                                const std::string& map_path, double tool_width_m) {
  std::vector<std::string> items;
  for (const FleetComparisonRow& r : rows) {
    items.push_back(absl::StrFormat(
        "    {\"planner\": %s, \"robots\": %d, \"makespan_s\": %.6g, \"lower_bound_s\": %.6g, "
        "\"gap\": %.6g, \"equal_area_makespan_s\": %.6g, \"equal_area_gap\": %.6g, "
        "\"cells_to_cover\": %d, \"covered_cells\": %d, \"planning_ms\": %.6g, "
        "\"termination\": %s}",
        JsonString(r.planner), r.robots, r.makespan_s, r.lower_bound_s, r.gap,
        r.equal_area_makespan_s, r.equal_area_gap, r.cells_to_cover, r.covered_cells, r.planning_ms,
        JsonString(r.termination)));
  }
  return absl::StrFormat(
      "{\n  \"map\": %s,\n  \"tool_width_m\": %.6g,\n  \"fleets\": [\n%s\n  ]\n}\n",
      JsonString(map_path), tool_width_m, absl::StrJoin(items, ",\n"));
}

int RunCompareCommand(const std::vector<std::string>& args) {
  return RunSubcommand("compare", kUsage, args, &Run);
}

}  // namespace covplan
