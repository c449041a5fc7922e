#include "client/replan_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "api/convert.h"
#include "api/geojson.h"
#include "client/args.h"
#include "client/remote.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan replan --plan-id P (--waypoint K --at X,Y | --distance D)\n"
    "                      [--obstacle AREA]... [--obstacle-cell ROW,COL]... [--obstacle-point X,Y]...\n"
    "                      [--method auto|ilp1|ilp2|greedy_detour|full] [--seed N]\n"
    "                      [--server HOST:PORT] [--deadline-ms D] [--out plan.json]\n"
    "                      [--map-id ID]   (routing metadata for a map-affine router)\n"
    "Reports obstacles the robot found while driving plan P (retained by the server)\n"
    "and prints the new plan for what is left, starting at the robot. --waypoint K is\n"
    "the segment being driven (the one ending at path[K]) and --at the robot's position\n"
    "on it; or --distance D metres driven along the path. AREA is a GeoJSON file or a\n"
    "ring \"x,y x,y x,y ...\" in metres (closed for you). The new plan's id continues\n"
    "the mission. The server defaults to 127.0.0.1:50051.\n";

absl::StatusOr<std::pair<double, double>> ParsePair(const std::string& flag, const std::string& text) {
  std::vector<std::string> parts = absl::StrSplit(text, ',');
  double a = 0, b = 0;
  if (parts.size() != 2 || !absl::SimpleAtod(parts[0], &a) || !absl::SimpleAtod(parts[1], &b)) {
    return absl::InvalidArgumentError(absl::StrCat("--", flag, " must be A,B, got '", text, "'"));
  }
  return std::make_pair(a, b);
}

absl::Status AddArea(const std::string& text, v1::Obstacles* out) {
  std::error_code ec;
  std::vector<PolygonInput> polygons;
  if (std::filesystem::is_regular_file(text, ec)) {
    std::ifstream in(text, std::ios::binary);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    ASSIGN_OR_RETURN(polygons, ParseGeoJsonPolygons(buffer.str(), text));
  } else {
    PolygonInput p;
    for (absl::string_view token : absl::StrSplit(text, ' ', absl::SkipEmpty())) {
      ASSIGN_OR_RETURN(auto xy, ParsePair("obstacle", std::string(token)));
      p.outer.push_back({xy.first, xy.second});
    }
    if (!p.outer.empty() && (p.outer.front().x != p.outer.back().x || p.outer.front().y != p.outer.back().y)) {
      p.outer.push_back(p.outer.front());
    }
    polygons.push_back(std::move(p));
  }
  PolygonsToProto(polygons, out->mutable_polygons());
  return absl::OkStatus();
}

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(ParsedArgs a,
                   ParseArgs(args, {"plan-id", "waypoint", "at", "distance", "method", "seed", "server",
                                    "deadline-ms", "out", "map-id"},
                             {}, {"obstacle", "obstacle-cell", "obstacle-point"}));
  v1::ReplanRequest request;
  if (!a.Get("plan-id")) return absl::InvalidArgumentError("--plan-id P is required");
  request.set_plan_id(*a.Get("plan-id"));
  ASSIGN_OR_RETURN(std::optional<int64_t> waypoint, a.GetInt("waypoint"));
  ASSIGN_OR_RETURN(std::optional<double> distance, a.GetDouble("distance"));
  if (waypoint.has_value() == distance.has_value()) {
    return absl::InvalidArgumentError("give --waypoint K with --at X,Y, or --distance D");
  }
  if (waypoint) {
    if (*waypoint < 1 || *waypoint > INT32_MAX) return absl::InvalidArgumentError("--waypoint must be >= 1");
    if (!a.Get("at")) return absl::InvalidArgumentError("--waypoint needs --at X,Y");
    ASSIGN_OR_RETURN(auto at, ParsePair("at", *a.Get("at")));
    request.mutable_progress()->set_waypoint(static_cast<int32_t>(*waypoint));
    request.mutable_progress()->mutable_position()->set_x(at.first);
    request.mutable_progress()->mutable_position()->set_y(at.second);
  } else {
    request.mutable_progress()->set_distance_m(*distance);
  }
  auto repeated = [&](const char* name) {
    auto it = a.repeated.find(name);
    return it == a.repeated.end() ? std::vector<std::string>{} : it->second;
  };
  for (const std::string& text : repeated("obstacle")) RETURN_IF_ERROR(AddArea(text, request.mutable_obstacles()));
  for (const std::string& text : repeated("obstacle-cell")) {
    ASSIGN_OR_RETURN(auto rc, ParsePair("obstacle-cell", text));
    v1::CellRef* cell = request.mutable_obstacles()->add_cells();
    cell->set_row(static_cast<int32_t>(rc.first));
    cell->set_col(static_cast<int32_t>(rc.second));
  }
  for (const std::string& text : repeated("obstacle-point")) {
    ASSIGN_OR_RETURN(auto xy, ParsePair("obstacle-point", text));
    v1::Point2* p = request.mutable_obstacles()->add_points();
    p->set_x(xy.first);
    p->set_y(xy.second);
  }
  if (auto m = a.Get("method")) {
    const std::map<std::string, v1::ReplanMethod> methods = {
        {"auto", v1::AUTO}, {"ilp1", v1::ILP1}, {"ilp2", v1::ILP2},
        {"greedy_detour", v1::GREEDY_DETOUR}, {"full", v1::FULL}};
    auto it = methods.find(*m);
    if (it == methods.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--method must be auto, ilp1, ilp2, greedy_detour or full, got '", *m, "'"));
    }
    request.set_method(it->second);
  }
  ASSIGN_OR_RETURN(std::optional<int64_t> seed, a.GetInt("seed"));
  if (seed) request.set_seed(static_cast<uint32_t>(*seed));
  ASSIGN_OR_RETURN(std::optional<int64_t> deadline_ms, a.GetInt("deadline-ms"));
  std::optional<absl::Duration> timeout;
  if (deadline_ms) {
    if (*deadline_ms <= 0) return absl::InvalidArgumentError("--deadline-ms must be positive");
    timeout = absl::Milliseconds(*deadline_ms);
  }
  const std::string server = a.Get("server").value_or("127.0.0.1:50051");
  absl::StatusOr<v1::ReplanResponse> response = RemotePlanner::Connect(server)->Replan(request, timeout, a.Get("map-id").value_or(""));
  if (!response.ok()) {
    return absl::Status(response.status().code(),
                        absl::StrCat("server ", server, " replied ",
                                     absl::StatusCodeToString(response.status().code()), ": ",
                                     response.status().message()));
  }
  std::fputs(FormatReplanSummary(*response).c_str(), stdout);
  if (auto out = a.Get("out")) {
    ASSIGN_OR_RETURN(std::string json, PlanToJson(response->plan()));
    std::ofstream file(*out, std::ios::binary | std::ios::trunc);
    file << json;
    if (!file) return absl::InvalidArgumentError(absl::StrCat("cannot write ", *out));
  }
  return absl::OkStatus();
}

}  // namespace

std::string FormatReplanSummary(const v1::ReplanResponse& r) {
  const v1::ReplanStats& s = r.replan();
  std::string detours;
  for (int k : s.greedy_detours()) absl::StrAppend(&detours, detours.empty() ? "" : ",", k);
  return absl::StrFormat(
      "plan       %s (replanned by %s)\n"
      "obstacles  %d new blocked cells, %d encounters on the path; greedy detours at [%s]\n"
      "replanned  at encounter %d, %.1f s ahead of the robot; %d new ranks (budget %d), %d kept, "
      "%d unchanged path pieces (%.1f m)\n"
      "coverage   %d cells swept before, %d left and swept by the new plan, %d cut off%s\n"
      "duration   %.1f s estimated for the rest\n"
      "timings    %.1f ms: ranks %.1f, transitions %.1f, tour %.1f ms\n",
      r.plan().plan_id(), s.method(), s.newly_blocked_cells(), s.num_encounters(), detours,
      s.replanned_encounter(), s.time_to_encounter_s(), s.new_ranks(), s.rank_budget(),
      s.kept_ranks(), s.kept_path_pieces(), s.kept_path_m(), s.covered_cells_before(),
      s.remaining_cells(), s.newly_unreachable_cells(),
      s.complete() ? "" : " (NOT complete: cells were cut off)", r.plan().stats().estimated_duration_s(),
      s.total_ms(), s.rank_replan_ms(), s.transitions_ms(), s.tour_ms());
}

int RunReplanCommand(const std::vector<std::string>& args) {
  return RunSubcommand("replan", kUsage, args, &Run);
}

}  // namespace covplan
