#include "client/fleet_plan.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "api/convert.h"
#include "api/convert_fleet.h"
#include "client/local_engine.h"
#include "client/remote.h"
#include "planner/common/status_macros.h"
#include "planner/fleet/fleet_planner.h"
#include "planner/plan/fleet_svg.h"

namespace covplan {
namespace {

constexpr char kRobotSyntax[] = "[ID=]X,Y[,THETA] (metres, radians)";

// Non-finite numbers (the closest approach of a single robot) are null.
// "converged" or "limit: time (detail)".
std::string TerminationText(const Termination& t) {
  if (!t.limit_reached()) return "converged";
  return absl::StrCat("limit: ", TerminationLimitName(t.limit),
                      t.detail.empty() ? "" : absl::StrCat(" (", t.detail, ")"));
}

std::string TerminationJson(const Termination& t) {
  return absl::StrFormat("{\"reason\": %s, \"limit\": %s, \"detail\": %s}",
                         JsonString(TerminationReasonName(t.reason)),
                         JsonString(TerminationLimitName(t.limit)), JsonString(t.detail));
}

std::string SafetyJson(const FleetSafety& s) {
  std::vector<std::string> conflicts;
  for (const FleetSafety::Conflict& c : s.conflicts) {
    conflicts.push_back(
        absl::StrFormat("{\"robot_a\": %s, \"robot_b\": %s, \"start_s\": %s, \"end_s\": %s, "
                        "\"min_distance_m\": %s}",
                        JsonString(c.robot_a), JsonString(c.robot_b), JsonNumber(c.start_s),
                        JsonNumber(c.end_s), JsonNumber(c.min_distance_m)));
  }
  return absl::StrFormat(
      "{\"clearance_m\": %s, \"closest_approach_m\": %s, \"closest_at_s\": %s, "
      "\"closest_pair\": [%s, %s], \"sample_step_s\": %s, \"conflicts\": [%s]}",
      JsonNumber(s.clearance_m), JsonNumber(s.closest_approach_m), JsonNumber(s.closest_at_s),
      JsonString(s.closest_pair[0]), JsonString(s.closest_pair[1]), JsonNumber(s.sample_step_s),
      absl::StrJoin(conflicts, ", "));
}

// Robot i's plan as plan.json holds a single plan, indented one level deeper.
absl::StatusOr<std::string> RobotPlanJson(const LocalFleetRun& run, size_t i,
                                          const std::string& plan_id) {
  const FleetRobotPlan& rp = run.plan.robots[i];
  RetainedPlan retained;
  retained.plan_id = absl::StrCat(plan_id, "-", rp.id);
  retained.map_id = run.map_id;
  retained.plan = rp.result.plan;
  retained.request = run.request.RobotRequest(i);
  v1::PlanResponse response;
  RetainedPlanToProto(retained, &response);
  ASSIGN_OR_RETURN(std::string json, PlanToJson(response));
  while (!json.empty() && json.back() == '\n') json.pop_back();
  return absl::StrReplaceAll(json, {{"\n", "\n      "}});
}

}  // namespace

std::set<std::string> FleetValueFlags() { return {"robots", "division", "clearance"}; }

absl::StatusOr<FleetRobot> ParseRobotFlag(const std::string& text, size_t index) {
  FleetRobot robot;
  robot.id = absl::StrCat("r", index + 1);
  std::string pose = text;
  if (const size_t eq = text.find('='); eq != std::string::npos) {
    robot.id = text.substr(0, eq);
    pose = text.substr(eq + 1);
    if (robot.id.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--robot must be ", kRobotSyntax, "; the ID before '=' is empty in '", text, "'"));
    }
  }
  std::optional<Pose2> start = ParseXyTheta(pose);
  if (!start) {
    return absl::InvalidArgumentError(
        absl::StrCat("--robot must be ", kRobotSyntax, ", got '", text, "'"));
  }
  robot.robot.start = *start;
  return robot;
}

absl::StatusOr<std::optional<FleetFlags>> ParseFleetFlags(const ParsedArgs& a) {
  const auto robot_flags = a.repeated.find(kRobotFlag);
  const bool robots_given = robot_flags != a.repeated.end() && !robot_flags->second.empty();
  ASSIGN_OR_RETURN(std::optional<int64_t> count, a.GetInt("robots"));
  if (!robots_given && !count) {
    if (a.Get("division") || a.Get("clearance")) {
      return absl::InvalidArgumentError(
          "--division and --clearance plan a fleet: give --robot X,Y (once per robot) or "
          "--robots K");
    }
    return std::optional<FleetFlags>();
  }
  if (robots_given && count) {
    return absl::InvalidArgumentError(
        "--robots K and --robot exclude each other (--robots: K robots without a start pose)");
  }
  FleetFlags flags;
  if (count) {
    if (*count < 1 || *count > FleetRequest::kMaxRobots) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--robots must be in [1, %d], got %d", FleetRequest::kMaxRobots, *count));
    }
    for (int64_t i = 0; i < *count; ++i) {
      FleetRobot robot;
      robot.id = absl::StrCat("r", i + 1);
      flags.robots.push_back(std::move(robot));
    }
  } else {
    std::map<std::string, size_t> seen;
    for (size_t i = 0; i < robot_flags->second.size(); ++i) {
      ASSIGN_OR_RETURN(FleetRobot robot, ParseRobotFlag(robot_flags->second[i], i));
      if (auto [it, fresh] = seen.emplace(robot.id, i); !fresh) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "--robot: robots %d and %d are both '%s' (ids default to r1, r2, ... by position)",
            it->second + 1, i + 1, robot.id));
      }
      flags.robots.push_back(std::move(robot));
    }
  }
  if (auto d = a.Get("division")) {
    ASSIGN_OR_RETURN(flags.division,
                     ParseChoice<FleetDivision>("division", *d,
                                                {{"makespan", FleetDivision::kMakespan},
                                                 {"equal_area", FleetDivision::kEqualArea}}));
  }
  ASSIGN_OR_RETURN(std::optional<double> clearance, a.GetDouble("clearance"));
  if (clearance) {
    if (*clearance < 0.0 || *clearance > 1e3) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--clearance must be in [0, 1000] metres, got %g", *clearance));
    }
    flags.clearance_m = *clearance;
  }
  return std::optional<FleetFlags>(std::move(flags));
}

FleetRequest MakeFleetRequest(const PlanRequest& base, const FleetFlags& flags) {
  FleetRequest request;
  request.base = base;
  request.division = flags.division;
  request.clearance_m = flags.clearance_m;
  for (const FleetRobot& given : flags.robots) {
    FleetRobot robot = given;
    robot.robot = base.common.robot;
    robot.robot.start = given.robot.start;
    // Without an explicit end the robot returns to its own start (the
    // robot model's default); --end, when given, applies to every robot.
    robot.robot.end = base.common.robot.end;
    robot.battery = base.battery;
    request.robots.push_back(std::move(robot));
  }
  return request;
}

absl::StatusOr<LocalFleetRun> PlanFleetLocally(const v1::PlanRequest& request,
                                               const FleetFlags& flags, const EngineLimits& limits,
                                               int num_threads,
                                               std::optional<GtspEffort> tour_effort) {
  if (!request.has_map()) return absl::InvalidArgumentError("local planning needs an inline map");
  LocalPlanOptions local_options;
  local_options.oarp_tour_effort = tour_effort;
  ASSIGN_OR_RETURN(PlanRequest base, PlanRequestFromProto(request, local_options));
  base.common.num_threads = std::max(1, num_threads);
  if (tour_effort && base.planner != "oarp")
    return absl::InvalidArgumentError("--tour-effort needs --planner oarp");
  LocalFleetRun run;
  run.request = MakeFleetRequest(base, flags);
  const LocalEngine local(limits);
  const MapSource source = MapSourceFor(request.map(), limits);
  run.map_id = source.map_id;
  ASSIGN_OR_RETURN(run.plan, PlanFleet(local.engine(), source, run.request));
  return run;
}

std::string FormatFleetSummary(const FleetRequest& request, const FleetPlan& plan) {
  const std::string planner =
      plan.robots.empty() ? request.base.planner : plan.robots[0].result.plan.planner;
  std::string out = absl::StrFormat(
      "fleet      %d robots, planner %s, division %s, %d cells to cover, %d swept\n"
      "robot      %-12s %8s %8s %12s %7s\n",
      plan.robots.size(), planner.empty() ? "default" : planner, FleetDivisionName(plan.division),
      plan.cover_cells, plan.covered_cells, "id", "cells", "share", "duration_s", "turns");
  for (const FleetRobotPlan& rp : plan.robots) {
    absl::StrAppendFormat(&out, "           %-12s %8d %6.1f %% %12.1f %7d%s\n", rp.id,
                          rp.assigned_cells, 100.0 * rp.area_share, rp.duration_s,
                          rp.result.plan.stats.num_turns,
                          rp.idle ? "  (idle: nothing to cover)" : "");
  }
  const FleetSafety& s = plan.safety;
  const std::string closest =
      std::isfinite(s.closest_approach_m)
          ? absl::StrFormat("closest approach %.2f m (%s and %s at %.1f s)", s.closest_approach_m,
                            s.closest_pair[0], s.closest_pair[1], s.closest_at_s)
          : std::string("closest approach: no second robot");
  absl::StrAppendFormat(&out,
                        "makespan   %.1f s, lower bound %.1f s, gap %.1f %%\n"
                        "sum        %.1f s of robot time (durations added)\n"
                        "planning   %.1f ms, %d rebalancing rounds, %s\n"
                        "safety     %s, %d clearance conflicts (closer than %.2f m)\n",
                        plan.makespan_s, plan.lower_bound_s, 100.0 * plan.gap, plan.sum_duration_s,
                        plan.planning_ms, plan.rebalance_rounds, TerminationText(plan.termination),
                        closest, s.conflicts.size(), s.clearance_m);
  if (plan.floor.reachable_area_m2 > 0.0) {
    absl::StrAppendFormat(&out,
                          "floor      %.1f %% of the %.1f m2 the tool can reach (%.1f m2 missed)\n",
                          100.0 * plan.floor.swept_reachable_ratio, plan.floor.reachable_area_m2,
                          plan.floor.missed_reachable_m2);
  }
  return out;
}

absl::StatusOr<std::string> FleetToJson(const LocalFleetRun& run, const std::string& map_path) {
  const FleetPlan& p = run.plan;
  const std::string plan_id =
      absl::StrFormat("local-fleet-%016x", std::random_device{}() * 0x9e3779b97f4a7c15ull);
  std::vector<std::string> robots;
  for (size_t i = 0; i < p.robots.size(); ++i) {
    const FleetRobotPlan& rp = p.robots[i];
    ASSIGN_OR_RETURN(std::string plan_json, RobotPlanJson(run, i, plan_id));
    robots.push_back(absl::StrFormat(
        "    {\n      \"id\": %s,\n      \"assigned_cells\": %d,\n      \"area_share\": %s,\n"
        "      \"duration_s\": %s,\n      \"idle\": %s,\n      \"plan\": %s\n    }",
        JsonString(rp.id), rp.assigned_cells, JsonNumber(rp.area_share), JsonNumber(rp.duration_s),
        rp.idle ? "true" : "false", plan_json));
  }
  return absl::StrFormat(
      "{\n  \"fleet_id\": %s,\n  \"map\": %s,\n  \"map_id\": %s,\n  \"division\": %s,\n"
      "  \"makespan_s\": %s,\n  \"lower_bound_s\": %s,\n  \"gap\": %s,\n"
      "  \"sum_duration_s\": %s,\n  \"cover_cells\": %d,\n  \"covered_cells\": %d,\n"
      "  \"rebalance_rounds\": %d,\n  \"planning_ms\": %s,\n  \"reachable_area_m2\": %s,\n"
      "  \"swept_reachable_ratio\": %s,\n  \"missed_reachable_m2\": %s,\n  \"termination\": %s,\n"
      "  \"safety\": %s,\n  \"robots\": [\n%s\n  ]\n}\n",
      JsonString(plan_id), JsonString(map_path), JsonString(run.map_id),
      JsonString(FleetDivisionName(p.division)), JsonNumber(p.makespan_s),
      JsonNumber(p.lower_bound_s), JsonNumber(p.gap), JsonNumber(p.sum_duration_s), p.cover_cells,
      p.covered_cells, p.rebalance_rounds, JsonNumber(p.planning_ms),
      JsonNumber(p.floor.reachable_area_m2), JsonNumber(p.floor.swept_reachable_ratio),
      JsonNumber(p.floor.missed_reachable_m2), TerminationJson(p.termination), SafetyJson(p.safety),
      absl::StrJoin(robots, ",\n"));
}

std::string FleetToSvg(const LocalFleetRun& run, const OccupancyMap* map, const SvgZones& zones) {
  std::vector<FleetSvgRobot> robots;
  std::shared_ptr<const Grid> grid;
  for (const FleetRobotPlan& rp : run.plan.robots) {
    robots.push_back({rp.id, &rp.result.plan, rp.duration_s});
    if (grid == nullptr) grid = rp.result.plan.grid;
  }
  if (grid == nullptr) return std::string();
  const std::string title = absl::StrFormat("%s division: makespan %.0f s (lower bound %.0f s)",
                                            FleetDivisionName(run.plan.division),
                                            run.plan.makespan_s, run.plan.lower_bound_s);
  return RenderFleetSvg(robots, *grid, map, zones, title);
}

absl::Status RunLocalFleet(const v1::PlanRequest& request, const FleetFlags& flags,
                           const EngineLimits& limits, const FleetRunOptions& options) {
  ASSIGN_OR_RETURN(LocalFleetRun run,
                   PlanFleetLocally(request, flags, limits, options.threads, options.tour_effort));
  std::fputs(FormatFleetSummary(run.request, run.plan).c_str(), stdout);
  if (options.out) {
    ASSIGN_OR_RETURN(std::string json, FleetToJson(run, options.map_path));
    RETURN_IF_ERROR(WriteTextFile(*options.out, json));
  }
  if (options.svg) {
    ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(request.map(), limits));
    SvgZones zones;
    zones.regions = PolygonsFromProto(request.regions());
    zones.no_go = PolygonsFromProto(request.no_go());
    RETURN_IF_ERROR(WriteTextFile(*options.svg, FleetToSvg(run, site.raster.get(), zones)));
  }
  return absl::OkStatus();
}

namespace {

// Writes the summary, --out and --svg of a fleet plan.
absl::Status WriteFleetRun(const LocalFleetRun& run, const v1::PlanRequest& request,
                           const EngineLimits& limits, const FleetRunOptions& options,
                           const std::string& json) {
  if (options.out) RETURN_IF_ERROR(WriteTextFile(*options.out, json));
  if (options.svg) {
    ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(request.map(), limits));
    SvgZones zones;
    zones.regions = PolygonsFromProto(request.regions());
    zones.no_go = PolygonsFromProto(request.no_go());
    RETURN_IF_ERROR(WriteTextFile(*options.svg, FleetToSvg(run, site.raster.get(), zones)));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status RunRemoteFleet(const Connection& server, const v1::PlanRequest& request,
                            const FleetFlags& flags, const EngineLimits& limits,
                            const FleetRunOptions& options, std::optional<absl::Duration> timeout) {
  if (!request.has_map()) return absl::InvalidArgumentError("the fleet's map must be inline");
  ASSIGN_OR_RETURN(PlanRequest base, PlanRequestFromProto(request));
  LocalFleetRun run;
  run.request = MakeFleetRequest(base, flags);
  std::unique_ptr<RemotePlanner> remote = RemotePlanner::Connect(server);
  v1::PutMapRequest put;
  *put.mutable_map() = request.map();
  put.set_name(options.map_path);
  absl::StatusOr<v1::PutMapResponse> stored = remote->PutMap(put, absl::Seconds(60));
  if (!stored.ok())
    return absl::Status(stored.status().code(), ServerError(server.target, stored.status()));
  v1::PlanRequest by_id = request;
  by_id.set_map_id(stored->map_id());
  v1::PlanFleetRequest fleet_request;
  FleetRequestToProto(run.request, by_id, &fleet_request);
  absl::StatusOr<v1::PlanFleetResponse> response = remote->PlanFleet(fleet_request, timeout);
  if (!response.ok())
    return absl::Status(response.status().code(), ServerError(server.target, response.status()));
  ASSIGN_OR_RETURN(run.plan, FleetPlanFromProto(*response));
  run.map_id = stored->map_id();
  std::fputs(FormatFleetSummary(run.request, run.plan).c_str(), stdout);
  std::printf("mission    %s\n", response->mission_id().c_str());
  ASSIGN_OR_RETURN(std::string json, ProtoToJson(*response));
  return WriteFleetRun(run, request, limits, options, json);
}

}  // namespace covplan
