#include "client/simulate_command.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "client/args.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/grid/grid.h"
#include "planner/grid/map_io.h"
#include "planner/plan/svg.h"
#include "planner/sim/clutter.h"
#include "planner/sim/simulator.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan simulate --map KNOWN [--resolution M] [--tool-width M]\n"
    "                        (--true-map TRUE | --clutter PCT) [--seed N]\n"
    "                        [--method auto|ilp1|ilp2|greedy_detour|full] [--sensor-range M]\n"
    "                        [--local | --server HOST:PORT [--watch SPEED]] [--svg run.svg]\n"
    "                        [--time-limit S] [--step S]\n"
    "                        [--tls-ca PEM] [--tls-cert PEM --tls-key PEM] [--token T | "
    "--token-file F]\n"
    "                        [--replan-tour-limit S] [--clutter-may-disconnect]\n"
    "                        [--no-offline-bound]\n"
    "                        [--max-speed M/S] [--acceleration M/S2] [--turn-rate DEG/S]\n"
    "                        [--free-thresh P] [--occupied-thresh P] [--negate]\n"
    "                        [--planner oarp|stc|boustrophedon]\n"
    "                        [--battery-capacity E --station X,Y[,THETA] [--reserve E]\n"
    "                         [--energy-per-metre E] [--energy-per-turn E] [--energy-per-second "
    "E]\n"
    "                         [--interruptible [--atomic-units ID,ID...]] [--recharge-s S]]\n"
    "                        [--robot [ID=]X,Y[,THETA]... | --robots K] [--fail-robot ID@S]...\n"
    "                        [--division makespan|equal_area] [--clearance M] [--out FILE]\n"
    "Plans OARP on KNOWN, drives the plan through the true map (TRUE, or KNOWN with\n"
    "random rotated rectangles over PCT % of its free area, placed with --seed) with a\n"
    "radial line-of-sight sensor (default 5.6 m), replans with --method (default auto)\n"
    "whenever new obstacles cut the path, and prints one JSON object: total_time_s =\n"
    "drive_time_s + stoppage_s, replans, coverage of the true map's free area, the\n"
    "floor the tool can reach on the true map and the share of it the driven path swept\n"
    "(reachable_area_m2, swept_reachable_ratio, missed_reachable_m2), and\n"
    "offline_lower_bound_s (OARP planned on the true map) and offline_cell_bound_s (OARP\n"
    "on the known map with the cells the true map blocks filled: the bound of the cell\n"
    "model the replanner and the simulated robot work in, which ignores new obstacles\n"
    "smaller than half a cell; length_in_obstacles_m says how far the robot drove\n"
    "through such). Nothing stands where the robot starts and ends: the true map is\n"
    "taken as KNOWN within a tool width of the plan's start and end poses\n"
    "(truth_cleared_px counts the pixels this freed; the bounds use that map too).\n"
    "Clutter rectangles have sides of 0.3-1.5 m and any orientation; one that would cut\n"
    "free cells of the tool-width grid off the rest is redrawn, unless\n"
    "--clutter-may-disconnect. --time-limit is the initial plan's search budget (default\n"
    "1 s), --replan-tour-limit the cap of each replan's tour search (default 1 s).\n"
    "--no-offline-bound skips planning the true map (offline_lower_bound_s is null).\n"
    "Maps are map_server .yaml files or bare .pgm/.png images (these need\n"
    "--resolution; --free-thresh, --occupied-thresh and --negate apply to them, a\n"
    "YAML names its own). Both maps must have the same size, resolution and origin.\n"
    "--local (the default) plans and replans in process. --server HOST:PORT asks that\n"
    "server instead: PutMap and Plan for the known map, then one Drive session in which\n"
    "every replan is an observation; the compute time charged then includes the network\n"
    "and the server's queue (the offline bounds are still computed locally).\n"
    "--watch SPEED (with --server) drives at SPEED times real time and reports the\n"
    "robot's progress on the session, so the web console shows it driving live.\n"
    "--svg draws the true map, the driven path, the replan points (blue) and the\n"
    "obstacle cells found (red).\n"
    "--planner plans with another registered planner (default oarp; the offline bounds\n"
    "use it too).\n"
    "With --battery-capacity and --station (as for covplan plan) the plan is split into\n"
    "charge cycles; the robot drives to the station at the end of each, recharges for\n"
    "--recharge-s seconds (default 0: give your dock's time) and resumes. The JSON adds\n"
    "charge_cycles_driven, recharge_time_s (in total_time_s), energy_used (the driven\n"
    "path under the energy model), min_battery_left (the lowest charge; below 0 the\n"
    "battery would have run flat), below_reserve, cycles_over_budget and\n"
    "cycle_energy. New obstacles on a battery plan are driven around by greedy_detour\n"
    "only (the station legs are kept; --method must be greedy_detour or absent); the\n"
    "cycles are not re-split, so a detour that makes a cycle too long shows in those\n"
    "figures. Clutter never covers the station (its surroundings within a tool width\n"
    "are kept as in KNOWN); the offline bounds include recharge-s per charge cycle.\n"
    "Battery runs are local only (not with --server).\n"
    "Fleets (local only, no battery): --robot [ID=]X,Y[,THETA] (repeatable) or --robots K\n"
    "plan K robots as `covplan plan` does (--division, --clearance); each drives its share\n"
    "through the true map, sensing and replanning as one robot does. --fail-robot\n"
    "ID@SECONDS (repeatable) stops that robot for good at that simulated time; what nobody\n"
    "has swept then is planned again among the survivors from where they stand. Prints per\n"
    "robot its swept cells and finish time, the makespan, each redivision's estimated\n"
    "makespan against the one achieved, and the reachable cells left unswept; --out writes\n"
    "them as JSON, --svg the driven paths (one colour per robot) on the true map.\n";

std::string JsonNumber(double v) { return std::isfinite(v) ? absl::StrFormat("%.6f", v) : "null"; }

absl::StatusOr<ReplanMethod> ParseMethod(const std::string& name) {
  for (ReplanMethod m : {ReplanMethod::kAuto, ReplanMethod::kIlp1, ReplanMethod::kIlp2,
                         ReplanMethod::kGreedyDetour, ReplanMethod::kFull}) {
    if (name == ReplanMethodName(m)) return m;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("--method must be auto, ilp1, ilp2, greedy_detour or full, got '", name, "'"));
}

// The true map with the driven path, replan points and found obstacles.
std::string RenderRunSvg(const OccupancyMap& truth, const Grid& grid, const SimulationResult& r,
                         const RobotModel& robot) {
  CoveragePlan drawn;
  drawn.grid = std::make_shared<const Grid>(grid);
  drawn.path = r.driven;
  drawn.stats = ComputePathStats(r.driven, robot);  // the legend: segments, turns, drive time
  for (const Waypoint& w : r.driven) drawn.stats.num_ranks += w.kind == SegmentKind::kCoverage;
  std::string svg = RenderPlanSvg(drawn, &truth);
  const double s = grid.cell_size();
  const double h = std::max(grid.rows() * s, truth.height() * truth.resolution());
  std::string extra =
      absl::StrFormat("<g transform=\"matrix(1 0 0 -1 0 %.4f)\">\n", h + 2 * grid.origin().y);
  absl::StrAppendFormat(&extra, "<g fill=\"none\" stroke=\"#d62728\" stroke-width=\"%.4f\">\n",
                        0.08 * s);
  for (const CellIndex& c : r.obstacles_found) {
    absl::StrAppendFormat(&extra, "<rect x=\"%.4f\" y=\"%.4f\" width=\"%.4f\" height=\"%.4f\"/>\n",
                          grid.origin().x + c.col * s, grid.origin().y + c.row * s, s, s);
  }
  absl::StrAppendFormat(&extra, "</g>\n<g fill=\"#1f5fa8\" fill-opacity=\"0.8\">\n");
  for (const Point2& p : r.replan_points) {
    absl::StrAppendFormat(&extra, "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"%.4f\"/>\n", p.x, p.y,
                          0.25 * s);
  }
  absl::StrAppend(&extra, "</g>\n</g>\n");
  const size_t end = svg.rfind("</svg>");
  svg.insert(end == std::string::npos ? svg.size() : end, extra);
  return svg;
}

// "X,Y[,THETA]" of --station.
absl::StatusOr<Pose2> ParseStation(const std::string& text) {
  std::vector<std::string> parts = absl::StrSplit(text, ',');
  Pose2 p;
  double* fields[] = {&p.x, &p.y, &p.theta};
  bool ok = parts.size() == 2 || parts.size() == 3;
  for (size_t i = 0; ok && i < parts.size(); ++i)
    ok = absl::SimpleAtod(parts[i], fields[i]) && std::isfinite(*fields[i]);
  if (!ok)
    return absl::InvalidArgumentError(
        absl::StrCat("--station must be X,Y[,THETA] (numbers), got '", text, "'"));
  return p;
}

// The battery flags; nullopt when none is given. Errors name the flag.
absl::StatusOr<std::optional<BatteryOptions>> ParseBattery(const ParsedArgs& a) {
  ASSIGN_OR_RETURN(std::optional<double> capacity, a.GetDouble("battery-capacity"));
  const bool any = capacity || a.Get("station") || a.Get("reserve") || a.Get("energy-per-metre") ||
                   a.Get("energy-per-turn") || a.Get("energy-per-second") ||
                   a.Has("interruptible") || a.Get("atomic-units") || a.Get("recharge-s");
  if (!any) return std::optional<BatteryOptions>();
  if (!capacity || !a.Get("station")) {
    return absl::InvalidArgumentError(
        "a battery needs --battery-capacity E and --station X,Y[,THETA]");
  }
  BatteryOptions b;
  b.capacity = *capacity;
  ASSIGN_OR_RETURN(b.station, ParseStation(*a.Get("station")));
  ASSIGN_OR_RETURN(std::optional<double> reserve, a.GetDouble("reserve"));
  if (reserve) b.reserve = *reserve;
  ASSIGN_OR_RETURN(std::optional<double> per_metre, a.GetDouble("energy-per-metre"));
  if (per_metre) b.energy.per_metre = *per_metre;
  ASSIGN_OR_RETURN(std::optional<double> per_turn, a.GetDouble("energy-per-turn"));
  if (per_turn) b.energy.per_turn = *per_turn;
  ASSIGN_OR_RETURN(std::optional<double> per_second, a.GetDouble("energy-per-second"));
  if (per_second) b.energy.per_second = *per_second;
  b.interruptible_units = a.Has("interruptible");
  if (auto ids = a.Get("atomic-units")) {
    for (absl::string_view id : absl::StrSplit(*ids, ',')) {
      int value = 0;
      if (!absl::SimpleAtoi(id, &value)) {
        return absl::InvalidArgumentError(
            absl::StrCat("--atomic-units must be unit ids separated by commas, got '", *ids, "'"));
      }
      b.atomic_units.push_back(value);
    }
  }
  return std::optional<BatteryOptions>(b);
}

// The planner's field names in a battery error, as the flags that set them.
absl::Status WithFlagNames(const absl::Status& status) {
  if (!absl::IsInvalidArgument(status)) return status;
  std::string m(status.message());
  // Longest names first: "battery.energy" is a prefix of the per-field ones.
  for (const auto& [field, flag] : std::vector<std::pair<std::string, std::string>>{
           {"battery.energy.per_metre", "--energy-per-metre"},
           {"battery.energy.per_turn", "--energy-per-turn"},
           {"battery.energy.per_second", "--energy-per-second"},
           {"battery.energy", "--energy-per-*"},
           {"battery.capacity", "--battery-capacity"},
           {"battery.reserve", "--reserve"},
           {"battery.station", "--station"},
           {"battery.atomic_units", "--atomic-units"},
           {"battery.interruptible_units", "--interruptible"},
           {"recharge_s", "--recharge-s"}}) {
    m = absl::StrReplaceAll(m, {{field, flag}});
  }
  return absl::InvalidArgumentError(m);
}

// The value flags `covplan simulate` accepts, besides the connection flags.
std::set<std::string> SimulateValueFlags() {
  return {"map",
          "resolution",
          "tool-width",
          "true-map",
          "clutter",
          "seed",
          "method",
          "sensor-range",
          "svg",
          "time-limit",
          "step",
          "max-speed",
          "acceleration",
          "turn-rate",
          "free-thresh",
          "occupied-thresh",
          "server",
          "watch",
          "replan-tour-limit",
          "planner",
          "battery-capacity",
          "station",
          "reserve",
          "energy-per-metre",
          "energy-per-turn",
          "energy-per-second",
          "atomic-units",
          "recharge-s"};
}

// Everything but the maps: seed, method, planner, battery, sensor, robot, time limit.
absl::Status ParseSimulationOptions(const ParsedArgs& a, SimulationOptions* o) {
  ASSIGN_OR_RETURN(std::optional<int64_t> seed, a.GetInt("seed"));
  if (seed && (*seed < 0 || *seed > UINT32_MAX))
    return absl::InvalidArgumentError("--seed must be in [0, 2^32)");
  o->seed = seed.value_or(1);
  if (auto m = a.Get("method")) {
    ASSIGN_OR_RETURN(o->method, ParseMethod(*m));
  }
  if (auto planner = a.Get("planner")) o->plan.planner = *planner;
  ASSIGN_OR_RETURN(o->plan.battery, ParseBattery(a));
  if (o->plan.battery) {
    if (a.Get("server"))
      return absl::InvalidArgumentError(
          "--battery-capacity: battery runs are local only, not with --server");
    if (a.Get("method") && o->method != ReplanMethod::kGreedyDetour) {
      return absl::InvalidArgumentError(
          "--method: battery plans are replanned with greedy_detour only (the other methods drop "
          "the station legs)");
    }
    o->method = ReplanMethod::kGreedyDetour;
    ASSIGN_OR_RETURN(std::optional<double> recharge, a.GetDouble("recharge-s"));
    o->recharge_s = recharge.value_or(0.0);
    if (!(o->recharge_s >= 0.0)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("--recharge-s must be >= 0 s, got %g", o->recharge_s));
    }
    RETURN_IF_ERROR(WithFlagNames(o->plan.battery->Validate()));
  }
  ASSIGN_OR_RETURN(std::optional<double> range, a.GetDouble("sensor-range"));
  if (range) o->sensor_range_m = *range;
  ASSIGN_OR_RETURN(std::optional<double> step, a.GetDouble("step"));
  if (step) o->step_s = *step;
  ASSIGN_OR_RETURN(std::optional<double> tour_limit, a.GetDouble("replan-tour-limit"));
  if (tour_limit) o->replan_tour_time_limit_s = *tour_limit;
  RobotModel& robot = o->plan.robot;
  ASSIGN_OR_RETURN(std::optional<double> tool, a.GetDouble("tool-width"));
  if (tool) robot.tool_width_m = *tool;
  ASSIGN_OR_RETURN(std::optional<double> speed, a.GetDouble("max-speed"));
  if (speed) robot.max_speed_mps = *speed;
  ASSIGN_OR_RETURN(std::optional<double> accel, a.GetDouble("acceleration"));
  if (accel) robot.acceleration_mps2 = *accel;
  ASSIGN_OR_RETURN(std::optional<double> turn, a.GetDouble("turn-rate"));
  if (turn) robot.turn_rate_deg_s = *turn;
  ASSIGN_OR_RETURN(std::optional<double> limit, a.GetDouble("time-limit"));
  o->plan.time_limit_s = limit.value_or(1.0);
  o->plan.seed = o->seed;
  if (!(o->plan.time_limit_s > 0.0 && o->plan.time_limit_s <= 3600.0)) {
    return absl::InvalidArgumentError("--time-limit must be in (0, 3600] s");
  }
  return absl::OkStatus();
}

// The map the simulated robot drives through.
struct TrueMap {
  OccupancyMap map;
  std::string name;  // as the JSON's true_map reports it
};

// --true-map TRUE as loaded, or `known` with --clutter PCT % of random rectangles.
absl::StatusOr<TrueMap> LoadTrueMap(const ParsedArgs& a, const OccupancyMap& known,
                                    const MapLoadOptions& load, const SimulationOptions& o) {
  const RobotModel& robot = o.plan.robot;
  TrueMap truth;
  if (auto path = a.Get("true-map")) {
    ASSIGN_OR_RETURN(truth.map, LoadMapFile(*path, load));
    truth.name = *path;
  } else {
    ASSIGN_OR_RETURN(std::optional<double> percent, a.GetDouble("clutter"));
    ClutterOptions clutter;
    if (!a.Has("clutter-may-disconnect")) clutter.keep_connected_cell_m = robot.tool_width_m;
    ASSIGN_OR_RETURN(truth.map, AddClutter(known, *percent, o.seed, clutter));
    if (o.plan.battery) {
      const Pose2& st = o.plan.battery->station;  // clutter kept off the station
      ClearAround(known, {st.x, st.y}, robot.tool_width_m, &truth.map);
    }
    truth.name = absl::StrFormat("clutter %g %% seed %d", *percent, o.seed);
  }
  return truth;
}

absl::Status WriteRunSvg(const std::string& svg_path, const OccupancyMap& truth,
                         const SimulationResult& r, const SimulationOptions& o) {
  const RobotModel& robot = o.plan.robot;
  GridOptions go;
  go.cell_size = robot.tool_width_m;
  go.min_free_fraction = o.plan.min_free_fraction;
  ASSIGN_OR_RETURN(Grid grid, BuildGrid(truth, go));
  std::ofstream out(svg_path, std::ios::binary | std::ios::trunc);
  out << RenderRunSvg(truth, grid, r, robot);
  out.close();
  if (!out) return absl::InvalidArgumentError(absl::StrCat("cannot write ", svg_path));
  return absl::OkStatus();
}

// One JSON object's fields, written in the order they are added.
class JsonObject {
 public:
  void Field(const char* name, const std::string& value) {
    absl::StrAppend(&text_, text_.size() > 1 ? ", " : "", "\"", name, "\": ", value);
  }
  std::string Close() const { return text_ + "}"; }

 private:
  std::string text_ = "{";
};

void AddBatteryFields(const BatteryRun& b, const SimulationOptions& o, JsonObject* json) {
  std::string energies = "[";
  for (size_t i = 0; i < b.cycle_energy.size(); ++i)
    absl::StrAppend(&energies, i ? "," : "", JsonNumber(b.cycle_energy[i]));
  energies += "]";
  json->Field("battery_capacity", JsonNumber(o.plan.battery->capacity));
  json->Field("battery_reserve", JsonNumber(o.plan.battery->reserve));
  json->Field("recharge_s", JsonNumber(o.recharge_s));
  json->Field("planned_charge_cycles", absl::StrCat(b.charge_cycles_planned));
  json->Field("planned_energy", JsonNumber(b.energy_planned));
  json->Field("charge_cycles_driven", absl::StrCat(b.charge_cycles_driven));
  json->Field("recharge_time_s", JsonNumber(b.recharge_time_s));
  json->Field("energy_used", JsonNumber(b.energy_used));
  json->Field("extra_energy", JsonNumber(b.energy_used - b.energy_planned));
  json->Field("min_battery_left", JsonNumber(b.min_battery_left));
  json->Field("below_reserve", b.below_reserve ? "true" : "false");
  json->Field("cycles_over_budget", absl::StrCat(b.cycles_over_budget));
  json->Field("ended_at_station", b.ended_at_station ? "true" : "false");
  json->Field("cycle_energy", energies);
}

std::string RunJson(const ParsedArgs& a, const SimulationOptions& o, const std::string& truth_name,
                    const SimulationResult& r, const OfflineBound& bound,
                    const OfflineBound& cell_bound, const std::vector<double>& reconnects) {
  const double total_ms = std::accumulate(r.replan_ms.begin(), r.replan_ms.end(), 0.0);
  double max_ms = 0.0;
  for (double ms : r.replan_ms) max_ms = std::max(max_ms, ms);
  // The first kMaxListedProblems problems; num_problems counts them all.
  constexpr size_t kMaxListedProblems = 20;
  std::string problems = "[";
  for (size_t i = 0; i < std::min(r.problems.size(), kMaxListedProblems); ++i)
    absl::StrAppend(&problems, i ? "," : "", JsonString(r.problems[i]));
  problems += "]";
  JsonObject json;
  json.Field("method", JsonString(ReplanMethodName(o.method)));
  json.Field("planner_at",
             JsonString(a.Get("server") ? absl::StrCat("server ", *a.Get("server")) : "local"));
  if (a.Get("server")) {
    // The Drive session's reconnects after its server went away.
    double longest = 0.0;
    for (double t : reconnects) longest = std::max(longest, t);
    json.Field("server_reconnects", absl::StrCat(reconnects.size()));
    json.Field("max_reconnect_s", JsonNumber(longest));
  }
  json.Field("true_map", JsonString(truth_name));
  json.Field("total_time_s", JsonNumber(r.total_time_s));
  json.Field("drive_time_s", JsonNumber(r.drive_time_s));
  json.Field("stoppage_s", JsonNumber(r.stoppage_s));
  json.Field("num_replans", absl::StrCat(r.num_replans));
  json.Field("num_encounters", absl::StrCat(r.num_encounters));
  json.Field("num_greedy_detours", absl::StrCat(r.num_greedy_detours));
  json.Field("num_turns", absl::StrCat(r.num_turns));
  json.Field("path_length_m", JsonNumber(r.path_length_m));
  json.Field("covered_free_area_ratio", JsonNumber(r.covered_free_area_ratio));
  json.Field("reachable_area_m2", JsonNumber(r.floor.reachable_area_m2));
  json.Field("swept_reachable_ratio", JsonNumber(r.floor.swept_reachable_ratio));
  json.Field("missed_reachable_m2", JsonNumber(r.floor.missed_reachable_m2));
  json.Field("mean_replan_ms",
             JsonNumber(r.replan_ms.empty() ? 0.0 : total_ms / r.replan_ms.size()));
  json.Field("max_replan_ms", JsonNumber(max_ms));
  json.Field("obstacle_cells_found", absl::StrCat(r.obstacles_found.size()));
  json.Field("touch_detections", absl::StrCat(r.num_touch_detections));
  json.Field("small_obstacles_found", absl::StrCat(r.num_small_obstacles));
  json.Field("truth_cleared_px", absl::StrCat(r.truth_cleared_px));
  json.Field("planned_duration_s", JsonNumber(r.planned_duration_s));
  json.Field("offline_lower_bound_s", JsonNumber(bound.duration_s));
  json.Field("offline_covered_free_area_ratio", JsonNumber(bound.covered_free_area_ratio));
  json.Field("offline_swept_reachable_ratio", JsonNumber(bound.swept_reachable_ratio));
  json.Field("offline_cell_bound_s", JsonNumber(cell_bound.duration_s));
  json.Field("length_in_obstacles_m", JsonNumber(r.length_in_obstacles_m));
  json.Field("completed", r.completed ? "true" : "false");
  json.Field("termination", JsonString(r.termination));
  json.Field("num_problems", absl::StrCat(r.problems.size()));
  json.Field("problems", problems);
  json.Field("planner", JsonString(o.plan.planner));
  if (r.battery) AddBatteryFields(*r.battery, o, &json);
  return json.Close();
}

}  // namespace

absl::StatusOr<std::string> SimulateCommandJson(const std::vector<std::string>& args,
                                                const RemotePlanSourceFactory& make_remote,
                                                const FleetSimulateHook* fleet) {
  std::set<std::string> value_flags = WithConnectionFlags(SimulateValueFlags());
  if (fleet != nullptr) value_flags.insert(fleet->value_flags.begin(), fleet->value_flags.end());
  ASSIGN_OR_RETURN(
      ParsedArgs a,
      ParseArgs(args, value_flags,
                {"local", "negate", "clutter-may-disconnect", "no-offline-bound", "interruptible"},
                fleet != nullptr ? fleet->repeatable_flags : std::set<std::string>()));
  if (a.Get("watch") && !a.Get("server"))
    return absl::InvalidArgumentError("--watch needs --server HOST:PORT: the run is watched there");
  if (a.Get("server") && a.Has("local"))
    return absl::InvalidArgumentError("give --local or --server, not both");
  if (a.Get("server") && a.Get("server")->empty())
    return absl::InvalidArgumentError("--server needs HOST:PORT");
  if (!a.Get("map")) return absl::InvalidArgumentError("--map KNOWN is required");
  if (a.Get("true-map").has_value() == a.Get("clutter").has_value()) {
    return absl::InvalidArgumentError("give exactly one of --true-map TRUE and --clutter PCT");
  }
  MapLoadOptions load;
  ASSIGN_OR_RETURN(std::optional<double> resolution, a.GetDouble("resolution"));
  if (resolution) load.resolution = *resolution, load.override_resolution = true;
  ASSIGN_OR_RETURN(std::optional<double> free_thresh, a.GetDouble("free-thresh"));
  if (free_thresh) load.free_thresh = *free_thresh;
  ASSIGN_OR_RETURN(std::optional<double> occupied_thresh, a.GetDouble("occupied-thresh"));
  if (occupied_thresh) load.occupied_thresh = *occupied_thresh;
  load.negate = a.Has("negate");

  SimulationOptions o;
  RETURN_IF_ERROR(ParseSimulationOptions(a, &o));

  ASSIGN_OR_RETURN(OccupancyMap known, LoadMapFile(*a.Get("map"), load));
  ASSIGN_OR_RETURN(TrueMap true_map, LoadTrueMap(a, known, load, o));
  OccupancyMap& truth = true_map.map;
  if (fleet != nullptr && fleet->wanted(a)) {
    if (a.Get("server")) return absl::InvalidArgumentError("fleet simulations are local only");
    if (o.plan.battery)
      return absl::InvalidArgumentError("--battery-capacity: fleet simulations take no battery");
    return fleet->run(a, known, truth, true_map.name, o);
  }
  std::unique_ptr<PlanSource> remote;
  if (auto server = a.Get("server")) {
    if (!make_remote) return absl::InvalidArgumentError("--server is not available in this build");
    SimulateRemoteFlags flags;
    flags.resolution = resolution;
    flags.free_thresh = free_thresh;
    flags.occupied_thresh = occupied_thresh;
    flags.negate = load.negate;
    ASSIGN_OR_RETURN(std::optional<double> watch, a.GetDouble("watch"));
    if (watch && !(*watch > 0.0 && *watch <= 1000.0))
      return absl::InvalidArgumentError("--watch: the speed-up must be in (0, 1000]");
    flags.watch_speed = watch.value_or(0.0);
    ASSIGN_OR_RETURN(Connection connection, ConnectionFromArgs(a, *server));
    ASSIGN_OR_RETURN(remote, make_remote(connection, *a.Get("map"), flags, o));
  }
  absl::StatusOr<SimulationResult> simulated = Simulate(known, truth, o, remote.get());
  if (!simulated.ok())
    return o.plan.battery ? WithFlagNames(simulated.status()) : simulated.status();
  const SimulationResult& r = *simulated;
  // The bounds and the picture use the true map the run drove (nothing on
  // the start and end poses: see SimulationResult::truth_cleared_px).
  if (r.truth_used != nullptr) truth = *r.truth_used;
  OfflineBound bound, cell_bound;
  bound.duration_s = bound.covered_free_area_ratio = bound.swept_reachable_ratio =
      cell_bound.duration_s = std::nan("");
  if (!a.Has("no-offline-bound")) {
    ASSIGN_OR_RETURN(bound, OfflineLowerBound(truth, o.plan));
    ASSIGN_OR_RETURN(OccupancyMap cells, CellLevelTruth(known, truth, o.plan));
    ASSIGN_OR_RETURN(cell_bound, OfflineLowerBound(cells, o.plan));
    bound.duration_s += o.recharge_s * bound.charge_cycles;
    cell_bound.duration_s += o.recharge_s * cell_bound.charge_cycles;
  }

  if (auto svg_path = a.Get("svg")) RETURN_IF_ERROR(WriteRunSvg(*svg_path, truth, r, o));

  return RunJson(a, o, true_map.name, r, bound, cell_bound,
                 remote != nullptr ? remote->ReconnectSeconds() : std::vector<double>());
}

namespace {

const RemotePlanSourceFactory* g_remote = nullptr;
const FleetSimulateHook* g_fleet = nullptr;

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(std::string json,
                   SimulateCommandJson(args, g_remote != nullptr ? *g_remote : nullptr, g_fleet));
  std::printf("%s\n", json.c_str());
  return absl::OkStatus();
}

}  // namespace

int RunSimulateCommand(const std::vector<std::string>& args, const RemotePlanSourceFactory& remote,
                       const FleetSimulateHook* fleet) {
  g_remote = &remote;
  g_fleet = fleet;
  const int rc = RunSubcommand("simulate", kUsage, args, &Run);
  g_remote = nullptr;
  g_fleet = nullptr;
  return rc;
}

}  // namespace covplan
