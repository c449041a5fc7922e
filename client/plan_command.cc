#include "client/plan_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "api/geojson.h"
#include "client/args.h"
#include "client/fleet_plan.h"
#include "client/geo_site.h"
#include "client/local_engine.h"
#include "client/map_flags.h"
#include "client/plan_exports.h"
#include "client/remote.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/grid/grid.h"
#include "planner/plan/svg.h"

namespace covplan {
namespace {

const char* PlanSourceText(v1::PlanSource s) {
  switch (s) {
    case v1::PLAN_SOURCE_CACHE_HIT:
      return "remembered plan";
    case v1::PLAN_SOURCE_IMPROVED:
      return "remembered plan, searched further";
    case v1::PLAN_SOURCE_WARM_START:
      return "warm-started from a remembered tour";
    default:
      return "cold";
  }
}

constexpr char kUsage[] =
    "usage: covplan plan --map FILE [--resolution M] [--tool-width M]\n"
    "                    [--local | --server HOST:PORT] [--out plan.json] [--svg plan.svg]\n"
    "                    [--tls-ca PEM] [--tls-cert PEM --tls-key PEM] [--token T | --token-file "
    "F]\n"
    "                    [--time-limit S] [--seed N] [--partition pushrelabel|matching|mincut|lp] "
    "[--tour gtsp|greedy]\n"
    "                    [--max-speed M/S] [--acceleration M/S2] [--turn-rate DEG/S]\n"
    "                    [--free-thresh P] [--occupied-thresh P] [--negate]\n"
    "                    [--min-free-fraction F] [--deadline-ms D] [--improve-remembered]\n"
    "                    [--threads N] [--tour-effort fast|default|thorough]   (--local)\n"
    "                    [--start X,Y[,THETA]] [--end X,Y[,THETA]] [--planner "
    "oarp|stc|boustrophedon]\n"
    "                    [--stc-tree dfs|prim] [--sweep-direction horizontal|vertical]\n"
    "                    [--stc-partial cover|discard] [--region AREA]... [--no-go AREA]...\n"
    "                    [--sweep-axis auto|vertical|horizontal]   (boustrophedon)\n"
    "                    [--battery-capacity E --station X,Y[,THETA] [--reserve E]\n"
    "                     [--energy-per-metre E] [--energy-per-turn E] [--energy-per-second E]\n"
    "                     [--interruptible [--atomic-units ID,ID...]]]\n"
    "                    [--robot [ID=]X,Y[,THETA]]... | [--robots K]   (a fleet)\n"
    "                    [--division makespan|equal_area] [--clearance M]\n"
    "                    [--out-geojson FILE] [--out-csv FILE]\n"
    "                    [--out-nav-path FILE [--frame-id ID] [--nav-stamp UNIX_S]]\n"
    "                    [--crs CRS]   (a .geojson map in EPSG:4326 lon/lat, a UTM zone...)\n"
    "--algorithm is another name for --planner. The --stc-* flags and --sweep-direction\n"
    "set the stc planner's options (--sweep-direction: the prim tree only).\n"
    "FILE is a map_server .yaml (with the image it names), a bare .pgm/.png (needs\n"
    "--resolution) or a .geojson polygon map (Polygon/MultiPolygon in metres; the free\n"
    "space). Without --local the server defaults to 127.0.0.1:50051.\n"
    "The server remembers plans: an identical request gets the remembered plan at once;\n"
    "--improve-remembered searches on from it within --time-limit instead.\n"
    "AREA is a GeoJSON file or a ring \"x,y x,y x,y ...\" in metres (closed for you):\n"
    "--region covers only the free cells mostly inside the regions (the rest of the\n"
    "map may still be driven through); --no-go is never entered. Both repeat.\n"
    "Poses are in metres in the map frame, THETA in radians (default 0). Without\n"
    "--start the robot starts at the first rank; without --end it returns to the start.\n"
    "A pose in a blocked cell next to a free one (a dock at a wall) joins the grid there.\n"
    "Fleets: each --robot is one robot starting at X,Y (ids r1, r2, ... unless ID= names\n"
    "it); --robots K plans K robots the planner spreads over the site. All share the\n"
    "robot flags (tool width, speeds, --end, battery); without --end each returns to its\n"
    "own start. --division makespan (default) divides the work so the last robot finishes\n"
    "early; equal_area gives each robot as many cells. --clearance M (default the tool\n"
    "width) is the distance the safety report counts robots coming closer than. Prints\n"
    "one line per robot and the fleet's makespan, lower bound and gap; --out writes the\n"
    "fleet JSON (each robot's plan as plan.json), --svg one picture of every robot.\n"
    "Exports (one robot's plan; a fleet's with covplan export): --out-geojson a GeoJSON\n"
    "FeatureCollection in the map frame (the path with per-vertex times_s and\n"
    "headings_rad, ranks, charge cycles, zones); --out-csv x,y,heading_rad,time_s,kind,rank\n"
    "per waypoint; --out-nav-path a nav_msgs/Path as JSON (--frame-id, default map;\n"
    "--nav-stamp, the start stamp in Unix seconds, default 0).\n"
    "--crs CRS: the .geojson map and every coordinate flag are in CRS (EPSG:4326 for\n"
    "longitude/latitude as RFC 7946 has them, or e.g. EPSG:32632); PROJ projects them onto\n"
    "a transverse Mercator centred on the site, where the plan is made (plan.json, the SVG\n"
    "and the nav path are in it); the GeoJSON and CSV exports are written back in CRS.\n";

// "X,Y" or "X,Y,THETA" (finite numbers) into `pose`.
absl::Status ParsePose(const std::string& flag, const std::string& text, v1::Pose* pose) {
  const std::optional<Pose2> p = ParseXyTheta(text);
  if (!p) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", flag, " must be X,Y or X,Y,THETA (metres, radians), got '", text, "'"));
  }
  pose->set_x(p->x);
  pose->set_y(p->y);
  pose->set_theta(p->theta);
  return absl::OkStatus();
}

// --region / --no-go: a GeoJSON file, or "x,y x,y x,y ..." (one ring, closed
// here if open).
absl::Status ParseArea(const std::string& flag, const std::string& text,
                       google::protobuf::RepeatedPtrField<v1::Polygon>* out) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(text, ec)) {
    std::ifstream in(text, std::ios::binary);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (!in.good() && !in.eof())
      return absl::InvalidArgumentError(absl::StrCat("cannot read ", text));
    ASSIGN_OR_RETURN(std::vector<PolygonInput> polygons, ParseGeoJsonPolygons(buffer.str(), text));
    PolygonsToProto(polygons, out);
    return absl::OkStatus();
  }
  PolygonInput polygon;
  for (absl::string_view token : absl::StrSplit(text, ' ', absl::SkipEmpty())) {
    std::vector<absl::string_view> xy = absl::StrSplit(token, ',');
    double x = 0, y = 0;
    if (xy.size() != 2 || !absl::SimpleAtod(xy[0], &x) || !absl::SimpleAtod(xy[1], &y)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--", flag, " must be a GeoJSON file or a ring \"x,y x,y x,y ...\"; '",
                       token, "' is neither a file nor an x,y point"));
    }
    polygon.outer.push_back({x, y});
  }
  if (!polygon.outer.empty() && (polygon.outer.front().x != polygon.outer.back().x ||
                                 polygon.outer.front().y != polygon.outer.back().y)) {
    polygon.outer.push_back(polygon.outer.front());
  }
  PolygonsToProto({polygon}, out);
  return absl::OkStatus();
}

struct PlanCommand {
  std::string map_path;
  MapFileOverrides overrides;
  v1::PlanRequest request;
  bool local = false;
  Connection server;
  std::optional<std::string> out;
  std::optional<std::string> svg;
  std::optional<int64_t> deadline_ms;
  int threads = 1;                        // --local only
  std::optional<GtspEffort> tour_effort;  // --local only
  std::optional<FleetFlags> fleet;        // --robot / --robots: a fleet plan
  PlanExports exports;                    // --out-geojson, --out-csv, --out-nav-path
  std::optional<std::string> crs;         // --crs: the map and coordinates in a CRS
};

// The value flags `covplan plan` accepts, besides the connection flags.
std::set<std::string> PlanValueFlags() {
  return {"map",
          "resolution",
          "tool-width",
          "server",
          "out",
          "svg",
          "time-limit",
          "seed",
          "partition",
          "tour",
          "max-speed",
          "acceleration",
          "turn-rate",
          "free-thresh",
          "occupied-thresh",
          "min-free-fraction",
          "deadline-ms",
          "start",
          "end",
          "planner",
          "battery-capacity",
          "station",
          "reserve",
          "energy-per-metre",
          "energy-per-turn",
          "energy-per-second",
          "atomic-units",
          "sweep-axis",
          "algorithm",
          "stc-tree",
          "sweep-direction",
          "stc-partial",
          "threads",
          "tour-effort",
          "crs"};
}

// --threads and --tour-effort: knobs of the in-process engine, so --local only.
absl::Status ParseLocalEngineFlags(const ParsedArgs& a, PlanCommand* c) {
  ASSIGN_OR_RETURN(std::optional<int64_t> threads, a.GetInt("threads"));
  if (threads) {
    if (!c->local)
      return absl::InvalidArgumentError("--threads needs --local (the server sets its own)");
    if (*threads < 1 || *threads > 256)
      return absl::InvalidArgumentError("--threads must be in [1, 256]");
    c->threads = static_cast<int>(*threads);
  }
  if (auto effort = a.Get("tour-effort")) {
    if (!c->local) return absl::InvalidArgumentError("--tour-effort needs --local");
    ASSIGN_OR_RETURN(c->tour_effort,
                     ParseChoice<GtspEffort>("tour-effort", *effort,
                                             {{"fast", GtspEffort::kFast},
                                              {"default", GtspEffort::kDefault},
                                              {"thorough", GtspEffort::kThorough}}));
  }
  return absl::OkStatus();
}

absl::Status ParseRobotFlags(const ParsedArgs& a, v1::RobotModel* robot) {
  ASSIGN_OR_RETURN(std::optional<double> tool, a.GetDouble("tool-width"));
  robot->set_tool_width_m(tool.value_or(0.8));
  ASSIGN_OR_RETURN(std::optional<double> speed, a.GetDouble("max-speed"));
  if (speed) robot->set_max_speed_mps(*speed);
  ASSIGN_OR_RETURN(std::optional<double> accel, a.GetDouble("acceleration"));
  if (accel) robot->set_acceleration_mps2(*accel);
  ASSIGN_OR_RETURN(std::optional<double> turn, a.GetDouble("turn-rate"));
  if (turn) robot->set_turn_rate_deg_s(*turn);
  if (auto start = a.Get("start"))
    RETURN_IF_ERROR(ParsePose("start", *start, robot->mutable_start()));
  if (auto end = a.Get("end")) RETURN_IF_ERROR(ParsePose("end", *end, robot->mutable_end()));
  return absl::OkStatus();
}

// --stc-tree, --sweep-direction and --stc-partial; `r`'s planner is already set.
absl::Status ParseStcFlags(const ParsedArgs& a, v1::PlanRequest* r) {
  if (!a.Get("stc-tree") && !a.Get("sweep-direction") && !a.Get("stc-partial"))
    return absl::OkStatus();
  if (r->planner() != "stc") {
    return absl::InvalidArgumentError(
        "--stc-tree, --sweep-direction and --stc-partial need --planner stc");
  }
  v1::StcOptions* stc = r->mutable_stc();
  if (auto t = a.Get("stc-tree")) {
    ASSIGN_OR_RETURN(v1::StcTree tree,
                     ParseChoice<v1::StcTree>(
                         "stc-tree", *t, {{"dfs", v1::STC_TREE_DFS}, {"prim", v1::STC_TREE_PRIM}}));
    stc->set_tree(tree);
  }
  if (auto d = a.Get("sweep-direction")) {
    ASSIGN_OR_RETURN(v1::StcSweepDirection direction,
                     ParseChoice<v1::StcSweepDirection>("sweep-direction", *d,
                                                        {{"horizontal", v1::STC_SWEEP_HORIZONTAL},
                                                         {"vertical", v1::STC_SWEEP_VERTICAL}}));
    stc->set_sweep_direction(direction);
  }
  if (auto m = a.Get("stc-partial")) {
    ASSIGN_OR_RETURN(v1::StcPartialCells partial,
                     ParseChoice<v1::StcPartialCells>(
                         "stc-partial", *m,
                         {{"cover", v1::STC_PARTIAL_COVER}, {"discard", v1::STC_PARTIAL_DISCARD}}));
    stc->set_partial_cells(partial);
  }
  return absl::OkStatus();
}

// The battery flags: none of them, or at least --battery-capacity and --station.
absl::Status ParseBatteryFlags(const ParsedArgs& a, v1::PlanRequest* r) {
  ASSIGN_OR_RETURN(std::optional<double> capacity, a.GetDouble("battery-capacity"));
  const bool battery = capacity || a.Get("station") || a.Get("reserve") ||
                       a.Get("energy-per-metre") || a.Get("energy-per-turn") ||
                       a.Get("energy-per-second") || a.Has("interruptible") ||
                       a.Get("atomic-units");
  if (!battery) return absl::OkStatus();
  if (!capacity || !a.Get("station")) {
    return absl::InvalidArgumentError(
        "a battery needs --battery-capacity E and --station X,Y[,THETA]");
  }
  v1::Battery* b = r->mutable_battery();
  b->set_capacity(*capacity);
  RETURN_IF_ERROR(ParsePose("station", *a.Get("station"), b->mutable_station()));
  ASSIGN_OR_RETURN(std::optional<double> reserve, a.GetDouble("reserve"));
  if (reserve) b->set_reserve(*reserve);
  ASSIGN_OR_RETURN(std::optional<double> per_metre, a.GetDouble("energy-per-metre"));
  if (per_metre) b->mutable_energy()->set_per_metre(*per_metre);
  ASSIGN_OR_RETURN(std::optional<double> per_turn, a.GetDouble("energy-per-turn"));
  if (per_turn) b->mutable_energy()->set_per_turn(*per_turn);
  ASSIGN_OR_RETURN(std::optional<double> per_second, a.GetDouble("energy-per-second"));
  if (per_second) b->mutable_energy()->set_per_second(*per_second);
  b->set_interruptible_units(a.Has("interruptible"));
  if (auto ids = a.Get("atomic-units")) {
    for (absl::string_view id : absl::StrSplit(*ids, ',')) {
      int value = 0;
      if (!absl::SimpleAtoi(id, &value)) {
        return absl::InvalidArgumentError(
            absl::StrCat("--atomic-units must be unit ids separated by commas, got '", *ids, "'"));
      }
      b->add_atomic_units(value);
    }
  }
  return absl::OkStatus();
}

// --sweep-axis (boustrophedon only), --partition and --tour.
absl::Status ParseSolverFlags(const ParsedArgs& a, v1::PlanRequest* r) {
  if (auto axis = a.Get("sweep-axis")) {
    if (r->planner() != "boustrophedon")
      return absl::InvalidArgumentError("--sweep-axis needs --planner boustrophedon");
    v1::BoustrophedonOptions* o = r->mutable_boustrophedon();
    ASSIGN_OR_RETURN(v1::SweepAxis sweep_axis,
                     ParseChoice<v1::SweepAxis>("sweep-axis", *axis,
                                                {{"auto", v1::SWEEP_AXIS_AUTO},
                                                 {"vertical", v1::SWEEP_AXIS_VERTICAL},
                                                 {"horizontal", v1::SWEEP_AXIS_HORIZONTAL}}));
    o->set_sweep_axis(sweep_axis);
  }
  if (auto p = a.Get("partition")) {
    ASSIGN_OR_RETURN(v1::PartitionSolver solver,
                     ParseChoice<v1::PartitionSolver>("partition", *p,
                                                      {{"pushrelabel", v1::PUSH_RELABEL},
                                                       {"matching", v1::MATCHING},
                                                       {"mincut", v1::MINCUT},
                                                       {"lp", v1::LP}}));
    r->set_partition_solver(solver);
  }
  if (auto t = a.Get("tour")) {
    ASSIGN_OR_RETURN(
        v1::TourSolver solver,
        ParseChoice<v1::TourSolver>("tour", *t, {{"gtsp", v1::GTSP}, {"greedy", v1::GREEDY}}));
    r->set_tour_solver(solver);
  }
  return absl::OkStatus();
}

// --robot / --robots and the fleet flags (fleet_plan.h): each robot's start
// comes from its --robot, not --start.
absl::Status ParseFleetPlanFlags(const ParsedArgs& a, PlanCommand* c) {
  ASSIGN_OR_RETURN(c->fleet, ParseFleetFlags(a));
  if (!c->fleet) return absl::OkStatus();
  if (a.Get("start")) {
    return absl::InvalidArgumentError(
        "--start is the single robot's start: give each robot's start with --robot "
        "[ID=]X,Y[,THETA]");
  }
  return absl::OkStatus();
}

absl::StatusOr<PlanCommand> ParsePlanCommand(const std::vector<std::string>& args) {
  std::set<std::string> value_flags = WithConnectionFlags(PlanValueFlags());
  value_flags.merge(FleetValueFlags());
  value_flags.merge(PlanExportFlags());
  ASSIGN_OR_RETURN(
      ParsedArgs a,
      ParseArgs(args, value_flags, {"local", "negate", "interruptible", "improve-remembered"},
                {"region", "no-go", kRobotFlag}));
  PlanCommand c;
  if (!a.Get("map")) return absl::InvalidArgumentError("--map FILE is required");
  c.map_path = *a.Get("map");
  if (a.Has("local") && a.Get("server")) {
    return absl::InvalidArgumentError("--local and --server exclude each other");
  }
  c.local = a.Has("local");
  ASSIGN_OR_RETURN(c.server, ConnectionFromArgs(a, a.Get("server").value_or(kDefaultServer)));
  c.out = a.Get("out");
  c.svg = a.Get("svg");
  ASSIGN_OR_RETURN(c.overrides, MapFileOverridesFromFlags(a));
  ASSIGN_OR_RETURN(c.deadline_ms, a.GetInt("deadline-ms"));
  if (c.deadline_ms && *c.deadline_ms <= 0) {
    return absl::InvalidArgumentError("--deadline-ms must be positive");
  }
  RETURN_IF_ERROR(ParseLocalEngineFlags(a, &c));
  RETURN_IF_ERROR(ParseFleetPlanFlags(a, &c));
  ASSIGN_OR_RETURN(c.exports, PlanExportsFromFlags(a));
  c.crs = a.Get("crs");
  if (c.fleet && c.exports.any()) {
    return absl::InvalidArgumentError(
        "--out-geojson, --out-csv and --out-nav-path export one robot's plan; for a fleet, "
        "write --out and export each robot's plan from it (covplan export --plan)");
  }

  v1::PlanRequest& r = c.request;
  RETURN_IF_ERROR(ParseRobotFlags(a, r.mutable_robot()));
  ASSIGN_OR_RETURN(std::optional<double> limit, a.GetDouble("time-limit"));
  if (limit) r.set_time_limit_s(*limit);
  r.set_improve_remembered(a.Has("improve-remembered"));
  ASSIGN_OR_RETURN(std::optional<double> fraction, a.GetDouble("min-free-fraction"));
  if (fraction) r.set_min_free_fraction(*fraction);
  ASSIGN_OR_RETURN(std::optional<int64_t> seed, a.GetInt("seed"));
  if (seed) {
    if (*seed < 0 || *seed > UINT32_MAX)
      return absl::InvalidArgumentError("--seed must be in [0, 2^32)");
    r.set_seed(static_cast<uint32_t>(*seed));
  }
  if (a.Get("planner") && a.Get("algorithm") && *a.Get("planner") != *a.Get("algorithm")) {
    return absl::InvalidArgumentError(
        "--algorithm is another name for --planner: give one of them");
  }
  if (auto p = a.Get("planner")) r.set_planner(*p);
  if (auto p = a.Get("algorithm")) r.set_planner(*p);
  RETURN_IF_ERROR(ParseStcFlags(a, &r));
  if (auto it = a.repeated.find("region"); it != a.repeated.end()) {
    for (const std::string& text : it->second)
      RETURN_IF_ERROR(ParseArea("region", text, r.mutable_regions()));
  }
  if (auto it = a.repeated.find("no-go"); it != a.repeated.end()) {
    for (const std::string& text : it->second)
      RETURN_IF_ERROR(ParseArea("no-go", text, r.mutable_no_go()));
  }
  RETURN_IF_ERROR(ParseBatteryFlags(a, &r));
  RETURN_IF_ERROR(ParseSolverFlags(a, &r));
  return c;
}

absl::StatusOr<v1::PlanResponse> Execute(const PlanCommand& c, const v1::Map& map,
                                         const EngineLimits& limits) {
  if (c.local) {
    v1::PlanRequest request = c.request;
    *request.mutable_map() = map;
    return PlanLocally(request, limits, c.threads, c.tour_effort);
  }
  std::unique_ptr<RemotePlanner> remote = RemotePlanner::Connect(c.server);
  v1::PutMapRequest put;
  *put.mutable_map() = map;
  put.set_name(c.map_path);
  absl::StatusOr<v1::PutMapResponse> stored = remote->PutMap(put, absl::Seconds(60));
  if (!stored.ok())
    return absl::Status(stored.status().code(), ServerError(c.server.target, stored.status()));
  v1::PlanRequest request = c.request;
  request.set_map_id(stored->map_id());
  std::optional<absl::Duration> timeout;
  if (c.deadline_ms) timeout = absl::Milliseconds(*c.deadline_ms);
  absl::StatusOr<v1::PlanResponse> plan = remote->Plan(request, timeout);
  if (!plan.ok())
    return absl::Status(plan.status().code(), ServerError(c.server.target, plan.status()));
  return plan;
}

absl::Status Run(const std::vector<std::string>& args) {
  absl::StatusOr<PlanCommand> parsed = ParsePlanCommand(args);
  if (!parsed.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(parsed.status().message(), " (see covplan plan --help)"));
  }
  PlanCommand c = *std::move(parsed);  // --crs projects its request
  EngineLimits limits;
  ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(c.map_path, c.overrides, limits));
  ASSIGN_OR_RETURN(std::optional<GeoFrame> frame,
                   ProjectIntoSite(c.crs, &map, &c.request, c.fleet ? &c.fleet->robots : nullptr));
  if (frame) {
    std::printf("frame      %s projected onto a transverse Mercator at %.7f, %.7f (lon, lat)\n",
                frame->crs().c_str(), frame->lon0(), frame->lat0());
  }
  if (c.fleet) {
    v1::PlanRequest request = c.request;
    *request.mutable_map() = map;
    const FleetRunOptions options{c.map_path, c.out, c.svg, c.threads, c.tour_effort};
    if (c.local) return RunLocalFleet(request, *c.fleet, limits, options);
    std::optional<absl::Duration> timeout;
    if (c.deadline_ms) timeout = absl::Milliseconds(*c.deadline_ms);
    return RunRemoteFleet(c.server, request, *c.fleet, limits, options, timeout);
  }
  ASSIGN_OR_RETURN(v1::PlanResponse response, Execute(c, map, limits));
  std::fputs(FormatPlanSummary(response).c_str(), stdout);
  if (c.out) {
    ASSIGN_OR_RETURN(std::string json, PlanToJson(response));
    RETURN_IF_ERROR(WriteTextFile(*c.out, json));
  }
  if (c.svg) {
    // In server mode the map is decoded here too, for the SVG background.
    ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(map, limits));
    ASSIGN_OR_RETURN(CoveragePlan plan, PlanFromProto(response));
    SvgZones zones;
    zones.regions = PolygonsFromProto(response.regions());
    zones.no_go = PolygonsFromProto(response.no_go());
    RETURN_IF_ERROR(WriteTextFile(*c.svg, RenderPlanSvg(plan, site.raster.get(), zones)));
  }
  return WritePlanExports(c.exports, response, ExportFrameOf(frame));
}

}  // namespace

absl::StatusOr<v1::PlanResponse> PlanLocally(const v1::PlanRequest& request,
                                             const EngineLimits& limits, int num_threads,
                                             std::optional<GtspEffort> tour_effort) {
  if (!request.has_map()) return absl::InvalidArgumentError("local planning needs an inline map");
  LocalPlanOptions local_options;
  local_options.oarp_tour_effort = tour_effort;
  ASSIGN_OR_RETURN(PlanRequest plan_request, PlanRequestFromProto(request, local_options));
  plan_request.common.num_threads = std::max(1, num_threads);
  if (tour_effort && plan_request.planner != "oarp")
    return absl::InvalidArgumentError("--tour-effort needs --planner oarp");
  const LocalEngine local(limits);
  const MapSource source = MapSourceFor(request.map(), limits);
  ASSIGN_OR_RETURN(EngineResult result, local.engine().Plan(source, plan_request));
  RetainedPlan retained;
  retained.plan_id = absl::StrFormat("local-%016x", std::random_device{}() * 0x9e3779b97f4a7c15ull);
  retained.map_id = source.map_id;
  retained.plan = std::move(result.plan);
  retained.request = std::move(plan_request);
  v1::PlanResponse response;
  RetainedPlanToProto(retained, &response);
  return response;
}

std::string FormatPlanSummary(const v1::PlanResponse& r) {
  const v1::PlanStats& s = r.stats();
  std::string stc;
  if (r.has_stc()) {
    const v1::StcDetail& d = r.stc();
    stc = absl::StrFormat(
        "stc        %d coarse cells (%d partly free, %d orphan sub-cells), %d extra moves, %d "
        "sub-cells "
        "covered twice%s\n",
        d.coarse_cells(), d.partial_coarse_cells(), d.orphan_cells(), d.extra_moves(),
        d.subcells_covered_twice(),
        d.discarded_cells() > 0 ? absl::StrFormat(", %d cells discarded", d.discarded_cells())
                                : "");
  }
  return absl::StrFormat(
             "plan       %s (map %s, planner %s)\n"
             "grid       %d x %d cells of %.3f m, %d to cover, %d swept (%d unreachable, not "
             "planned)%s\n"
             "ranks      %d (partition %s)\n"
             "tour       %s, %d turns, %s\n"
             "length     coverage %.1f m, transitions %.1f m\n"
             "coverage   %.1f %% of the free area%s\n"
             "duration   %.1f s estimated (turning %.1f s)\n"
             "timings    planning %.1f ms: grid %.1f, partition %.1f, transitions %.1f, tour %.1f "
             "ms%s\n",
             r.plan_id(), r.map_id().substr(0, 12), r.planner(), s.grid_rows(), s.grid_cols(),
             r.grid().cell_size_m(), s.free_cells(), s.covered_cells(), s.unreachable_free_cells(),
             s.no_go_cells() > 0 ? absl::StrFormat(", %d closed by no-go zones", s.no_go_cells())
                                 : "",
             s.num_ranks(), s.partition_solver(), s.tour_solver(), s.num_turns(),
             r.termination().detail().empty() ? "converged" : r.termination().detail(),
             s.coverage_length_m(), s.transition_length_m(), 100.0 * s.covered_free_area_ratio(),
             s.reachable_area_m2() > 0.0
                 ? absl::StrFormat("; %.1f %% of the %.1f m2 the tool can reach (%.1f m2 missed)",
                                   100.0 * s.swept_reachable_ratio(), s.reachable_area_m2(),
                                   s.missed_reachable_m2())
                 : "",
             s.estimated_duration_s(), s.turning_time_s(), s.planning_ms(), s.grid_ms(),
             s.partition_ms(), s.transitions_ms(), s.tour_ms(),
             absl::StrCat(s.decomposition_cached() ? " (decomposition cached)" : "",
                          s.plan_source() == v1::PLAN_SOURCE_COLD ||
                                  s.plan_source() == v1::PLAN_SOURCE_UNSPECIFIED
                              ? ""
                              : absl::StrCat(" (", PlanSourceText(s.plan_source()), ")"))) +
         (r.cycles().empty()
              ? std::string()
              : absl::StrFormat(
                    "battery    %d charge cycles, energy %.1f (unconstrained %.1f, bound %.1f)\n",
                    s.charge_cycles(), s.energy_total(), s.energy_unconstrained(),
                    s.energy_lower_bound())) +
         stc;
}

int RunPlanCommand(const std::vector<std::string>& args) {
  return RunSubcommand("plan", kUsage, args, &Run);
}

}  // namespace covplan
