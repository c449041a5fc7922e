#include "client/simulate_fleet.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/args.h"
#include "client/fleet_plan.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/plan/fleet_svg.h"

namespace covplan {
namespace {

constexpr char kFailRobotFlag[] = "fail-robot";

std::string Number(double v) {
  return std::isfinite(v) ? absl::StrFormat("%.6f", v) : std::string("null");
}

double Ratio(const FleetRedivision& d) {
  return d.plan.makespan_s > 0.0 ? d.achieved_s / d.plan.makespan_s : std::nan("");
}

bool Wanted(const ParsedArgs& a) {
  for (const char* flag : {kRobotFlag, kFailRobotFlag}) {
    const auto it = a.repeated.find(flag);
    if (it != a.repeated.end() && !it->second.empty()) return true;
  }
  return a.Get("robots") || a.Get("division") || a.Get("clearance") || a.Get("out");
}

// Every --fail-robot, each naming a robot of `fleet` once.
absl::StatusOr<std::vector<RobotFailure>> ParseFailures(const ParsedArgs& a,
                                                        const FleetRequest& fleet) {
  std::vector<RobotFailure> failures;
  const auto it = a.repeated.find(kFailRobotFlag);
  if (it == a.repeated.end()) return failures;
  std::vector<std::string> ids;
  for (const FleetRobot& r : fleet.robots) ids.push_back(r.id);
  std::map<std::string, int> seen;
  for (const std::string& text : it->second) {
    ASSIGN_OR_RETURN(RobotFailure f, ParseFailRobot(text));
    if (std::find(ids.begin(), ids.end(), f.robot_id) == ids.end()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--fail-robot: no robot '%s' in the fleet (its robots: %s)", f.robot_id,
                          absl::StrJoin(ids, ", ")));
    }
    if (seen[f.robot_id]++ > 0) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--fail-robot: robot '%s' fails twice", f.robot_id));
    }
    failures.push_back(std::move(f));
  }
  return failures;
}

std::string LegJson(const FleetLeg& leg) {
  return absl::StrFormat(
      "{\"start_s\": %s, \"end_s\": %s, \"interrupted\": %s, \"planned_duration_s\": %s, "
      "\"drive_time_s\": %s, \"stoppage_s\": %s, \"num_replans\": %d, \"completed\": %s}",
      Number(leg.start_s), Number(leg.end_s), leg.interrupted ? "true" : "false",
      Number(leg.plan.stats.estimated_duration_s), Number(leg.run.drive_time_s),
      Number(leg.run.stoppage_s), leg.run.num_replans, leg.run.completed ? "true" : "false");
}

std::string RobotJson(const FleetRobotRun& run) {
  std::vector<std::string> legs;
  for (const FleetLeg& leg : run.legs) legs.push_back(LegJson(leg));
  return absl::StrFormat(
      "    {\"id\": %s, \"failed\": %s, \"failed_at_s\": %s, \"finish_s\": %s, \"swept_cells\": "
      "%d, \"num_replans\": "
      "%d, \"stoppage_s\": %s, \"length_in_obstacles_m\": %s,\n     \"legs\": [%s]}",
      JsonString(run.id), run.failed ? "true" : "false",
      run.failed ? Number(run.failed_at_s) : std::string("null"), Number(run.finish_s),
      run.swept_cells, run.num_replans, Number(run.stoppage_s), Number(run.length_in_obstacles_m),
      absl::StrJoin(legs, ", "));
}

std::string RedivisionJson(const FleetRedivision& d) {
  std::vector<std::string> robots;
  for (const std::string& id : d.robots) robots.push_back(JsonString(id));
  return absl::StrFormat(
      "    {\"time_s\": %s, \"failed_robot\": %s, \"left_cells\": %d, \"robots\": [%s], "
      "\"estimated_makespan_s\": %s, \"lower_bound_s\": %s, \"achieved_s\": %s, "
      "\"achieved_over_estimated\": %s}",
      Number(d.time_s), JsonString(d.failed_robot), d.left_cells, absl::StrJoin(robots, ", "),
      Number(d.plan.makespan_s), Number(d.plan.lower_bound_s), Number(d.achieved_s),
      Number(Ratio(d)));
}

std::string ResultJson(const FleetSimulationResult& r, const ParsedArgs& a,
                       const std::string& truth_name, const SimulationOptions& o) {
  std::vector<std::string> robots, redivisions, problems;
  for (const FleetRobotRun& run : r.robots) robots.push_back(RobotJson(run));
  for (const FleetRedivision& d : r.redivisions) redivisions.push_back(RedivisionJson(d));
  for (const std::string& p : r.problems) problems.push_back(JsonString(p));
  std::vector<std::string> unswept;
  for (const CellIndex& c : r.unswept_reachable)
    unswept.push_back(absl::StrFormat("[%d, %d]", c.row, c.col));
  return absl::StrFormat(
      "{\n  \"map\": %s,\n  \"true_map\": %s,\n  \"planner\": %s,\n  \"method\": %s,\n"
      "  \"planned_makespan_s\": %s,\n  \"makespan_s\": %s,\n  \"mission_cells\": %d,\n"
      "  \"swept_cells\": %d,\n  \"reachable_cells\": %d,\n  \"unswept_reachable_cells\": %d,\n"
      "  \"unswept_reachable\": [%s],\n"
      "  \"covered_free_area_ratio\": %s,\n  \"reachable_area_m2\": %s,\n"
      "  \"swept_reachable_ratio\": %s,\n  \"missed_reachable_m2\": %s,\n"
      "  \"length_in_obstacles_m\": %s,\n"
      "  \"completed\": %s,\n  \"problems\": [%s],\n  \"redivisions\": [\n%s\n  ],\n"
      "  \"robots\": [\n%s\n  ]\n}\n",
      JsonString(a.Get("map").value_or("")), JsonString(truth_name), JsonString(o.plan.planner),
      JsonString(ReplanMethodName(o.method)), Number(r.initial.makespan_s), Number(r.makespan_s),
      r.mission_cells, r.swept_cells, r.reachable_cells, r.unswept_reachable_cells,
      absl::StrJoin(unswept, ", "), Number(r.covered_free_area_ratio),
      Number(r.floor.reachable_area_m2), Number(r.floor.swept_reachable_ratio),
      Number(r.floor.missed_reachable_m2), Number(r.length_in_obstacles_m),
      r.completed ? "true" : "false", absl::StrJoin(problems, ", "),
      absl::StrJoin(redivisions, ",\n"), absl::StrJoin(robots, ",\n"));
}

// The driven paths on the true map, each robot's swept cells tinted.
std::string DrivenSvg(const FleetSimulationResult& r, const OccupancyMap& truth) {
  const std::shared_ptr<const Grid> grid =
      r.initial.robots.empty() ? nullptr : r.initial.robots[0].result.plan.grid;
  if (grid == nullptr) return std::string();
  std::vector<CoveragePlan> drawn(r.robots.size());
  std::vector<FleetSvgRobot> robots;
  for (size_t i = 0; i < r.robots.size(); ++i) {
    const FleetRobotRun& run = r.robots[i];
    drawn[i].grid = grid;
    drawn[i].path = run.driven;
    CoverageSweep all;
    all.waypoint = -1;
    for (size_t c = 0; c < run.swept.size(); ++c) {
      if (run.swept[c]) all.cells.push_back(grid->FromIndex(static_cast<int64_t>(c)));
    }
    drawn[i].sweeps.push_back(std::move(all));
    robots.push_back({run.failed ? run.id + " (failed)" : run.id, &drawn[i], run.finish_s});
  }
  std::string title = absl::StrFormat("driven: makespan %.0f s (planned %.0f s)", r.makespan_s,
                                      r.initial.makespan_s);
  for (const FleetRedivision& d : r.redivisions) {
    absl::StrAppendFormat(&title, "; %s failed at %.0f s", d.failed_robot, d.time_s);
  }
  return RenderFleetSvg(robots, *grid, &truth, {}, title);
}

absl::StatusOr<std::string> RunFleet(const ParsedArgs& a, const OccupancyMap& known,
                                     const OccupancyMap& truth, const std::string& truth_name,
                                     const SimulationOptions& o) {
  ASSIGN_OR_RETURN(std::optional<FleetFlags> flags, ParseFleetFlags(a));
  if (!flags) {
    if (auto it = a.repeated.find(kFailRobotFlag); it != a.repeated.end()) {
      for (const std::string& text : it->second) RETURN_IF_ERROR(ParseFailRobot(text).status());
    }
    return absl::InvalidArgumentError(
        "--fail-robot and --out simulate a fleet: give --robot X,Y (once per robot) or --robots K");
  }
  FleetSimulationOptions options;
  options.fleet = MakeFleetRequest(o.plan.ToRequest(), *flags);
  options.sim = o;
  ASSIGN_OR_RETURN(options.failures, ParseFailures(a, options.fleet));
  ASSIGN_OR_RETURN(FleetSimulationResult r, SimulateFleet(known, truth, options));
  const OccupancyMap& driven_on = r.truth_used != nullptr ? *r.truth_used : truth;
  if (auto out = a.Get("out"))
    RETURN_IF_ERROR(WriteTextFile(*out, ResultJson(r, a, truth_name, o)));
  if (auto svg = a.Get("svg")) RETURN_IF_ERROR(WriteTextFile(*svg, DrivenSvg(r, driven_on)));
  std::string summary = FormatFleetSimulation(r);
  while (!summary.empty() && summary.back() == '\n') summary.pop_back();
  return summary;
}

}  // namespace

const FleetSimulateHook& FleetSimulation() {
  static const FleetSimulateHook* const hook = [] {
    auto* h = new FleetSimulateHook;
    h->value_flags = FleetValueFlags();
    h->value_flags.insert("out");
    h->repeatable_flags = {kRobotFlag, kFailRobotFlag};
    h->wanted = &Wanted;
    h->run = &RunFleet;
    return h;
  }();
  return *hook;
}

absl::StatusOr<RobotFailure> ParseFailRobot(const std::string& text) {
  RobotFailure f;
  const size_t at = text.rfind('@');
  bool ok = at != std::string::npos && at > 0;
  if (ok) {
    f.robot_id = text.substr(0, at);
    ok = absl::SimpleAtod(text.substr(at + 1), &f.time_s) && std::isfinite(f.time_s) &&
         f.time_s >= 0.0;
  }
  if (!ok) {
    return absl::InvalidArgumentError(
        absl::StrCat("--fail-robot must be ID@SECONDS (a robot's id and the simulated time it "
                     "fails at, seconds >= 0), got '",
                     text, "'"));
  }
  return f;
}

std::string FormatFleetSimulation(const FleetSimulationResult& r) {
  std::string out = absl::StrFormat(
      "fleet      %d robots, %d cells to cover on the known map, planned makespan %.1f s\n"
      "robot      %-12s %11s %10s %5s %8s\n",
      r.robots.size(), r.mission_cells, r.initial.makespan_s, "id", "swept_cells", "finish_s",
      "legs", "replans");
  for (const FleetRobotRun& run : r.robots) {
    absl::StrAppendFormat(
        &out, "           %-12s %11d %10.1f %5d %8d%s\n", run.id, run.swept_cells, run.finish_s,
        run.legs.size(), run.num_replans,
        !run.failed ? std::string()
        : run.legs.empty() || !run.legs.back().interrupted
            ? absl::StrFormat("  failed at %.1f s, after its end", run.failed_at_s)
            : absl::StrFormat("  failed, stopped at %.1f s", run.finish_s));
  }
  absl::StrAppendFormat(&out, "makespan   %.1f s driven (planned %.1f s)\n", r.makespan_s,
                        r.initial.makespan_s);
  for (const FleetRedivision& d : r.redivisions) {
    if (d.left_cells == 0 || d.robots.empty() || d.plan.robots.empty()) {
      absl::StrAppendFormat(&out, "failure    %s at %.1f s: %d cells left, %d robots left\n",
                            d.failed_robot, d.time_s, d.left_cells, d.robots.size());
      continue;
    }
    absl::StrAppendFormat(
        &out,
        "failure    %s at %.1f s: %d cells left, redivided among %s\n"
        "redivision estimated makespan %.1f s (lower bound %.1f s); achieved %.1f s after the "
        "failure, ratio %.3f\n",
        d.failed_robot, d.time_s, d.left_cells, absl::StrJoin(d.robots, ", "), d.plan.makespan_s,
        d.plan.lower_bound_s, d.achieved_s, Ratio(d));
  }
  absl::StrAppendFormat(
      &out,
      "unswept    %d reachable cells of %d (swept %d cells, %.4f of the true "
      "map's free area)\n"
      "floor      %.2f %% of the %.1f m2 the tool can reach swept (%.1f m2 missed)\n"
      "obstacles  %.2f m driven inside obstacles smaller than half a cell\n",
      r.unswept_reachable_cells, r.reachable_cells, r.swept_cells, r.covered_free_area_ratio,
      100.0 * r.floor.swept_reachable_ratio, r.floor.reachable_area_m2, r.floor.missed_reachable_m2,
      r.length_in_obstacles_m);
  if (!r.completed) absl::StrAppend(&out, "incomplete a bound of the simulation stopped a robot\n");
  for (const std::string& p : r.problems) absl::StrAppend(&out, "problem    ", p, "\n");
  return out;
}

}  // namespace covplan
