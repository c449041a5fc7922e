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
    "                      [--obstacle AREA]... [--obstacle-cell ROW,COL]... [--obstacle-point "
    "X,Y]...\n"
    "                      [--method auto|ilp1|ilp2|greedy_detour|full] [--seed N]\n"
    "                      [--server HOST:PORT] [--deadline-ms D] [--out plan.json]\n"
    "                      [--tls-ca PEM] [--tls-cert PEM --tls-key PEM] [--token T | --token-file "
    "F]\n"
    "                      [--map-id ID]   (routing metadata for a map-affine router)\n"
    "Reports obstacles the robot found while driving plan P (retained by the server)\n"
    "and prints the new plan for what is left, starting at the robot. --waypoint K is\n"
    "the segment being driven (the one ending at path[K]) and --at the robot's position\n"
    "on it; or --distance D metres driven along the path. AREA is a GeoJSON file or a\n"
    "ring \"x,y x,y x,y ...\" in metres (closed for you). The new plan's id continues\n"
    "the mission. The server defaults to 127.0.0.1:50051.\n";

absl::StatusOr<std::pair<double, double>> ParsePair(const std::string& flag,
                                                    const std::string& text) {
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
    if (!p.outer.empty() &&
        (p.outer.front().x != p.outer.back().x || p.outer.front().y != p.outer.back().y)) {
      p.outer.push_back(p.outer.front());
    }
    polygons.push_back(std::move(p));
  }
  PolygonsToProto(polygons, out->mutable_polygons());
  return absl::OkStatus();
}

absl::Status ParseObstacleFlags(const ParsedArgs& a, v1::Obstacles* obstacles) {
  auto repeated = [&](const char* name) {
    auto it = a.repeated.find(name);
    return it == a.repeated.end() ? std::vector<std::string>{} : it->second;
  };
  for (const std::string& text : repeated("obstacle")) RETURN_IF_ERROR(AddArea(text, obstacles));
  for (const std::string& text : repeated("obstacle-cell")) {
    ASSIGN_OR_RETURN(auto rc, ParsePair("obstacle-cell", text));
    v1::CellRef* cell = obstacles->add_cells();
    cell->set_row(static_cast<int32_t>(rc.first));
    cell->set_col(static_cast<int32_t>(rc.second));
  }
  for (const std::string& text : repeated("obstacle-point")) {
    ASSIGN_OR_RETURN(auto xy, ParsePair("obstacle-point", text));
    v1::Point2* p = obstacles->add_points();
    p->set_x(xy.first);
    p->set_y(xy.second);
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::ReplanMethod> ParseMethodFlag(const ParsedArgs& a) {
  auto m = a.Get("method");
  if (!m) return v1::REPLAN_METHOD_UNSPECIFIED;
  const std::map<std::string, v1::ReplanMethod> methods = {{"auto", v1::AUTO},
                                                           {"ilp1", v1::ILP1},
                                                           {"ilp2", v1::ILP2},
                                                           {"greedy_detour", v1::GREEDY_DETOUR},
                                                           {"full", v1::FULL}};
  auto it = methods.find(*m);
  if (it == methods.end()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--method must be auto, ilp1, ilp2, greedy_detour or full, got '", *m, "'"));
  }
  return it->second;
}

absl::StatusOr<std::optional<absl::Duration>> ParseDeadlineFlag(const ParsedArgs& a) {
  ASSIGN_OR_RETURN(std::optional<int64_t> deadline_ms, a.GetInt("deadline-ms"));
  if (!deadline_ms) return std::optional<absl::Duration>();
  if (*deadline_ms <= 0) return absl::InvalidArgumentError("--deadline-ms must be positive");
  return std::optional<absl::Duration>(absl::Milliseconds(*deadline_ms));
}

absl::Status WriteReply(const ParsedArgs& a, const std::string& server,
                        const absl::StatusOr<v1::ReplanResponse>& response) {
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

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(
      ParsedArgs a,
      ParseArgs(args,
                WithConnectionFlags({"plan-id", "waypoint", "at", "distance", "method", "seed",
                                     "server", "deadline-ms", "out", "map-id"}),
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
    if (*waypoint < 1 || *waypoint > INT32_MAX)
      return absl::InvalidArgumentError("--waypoint must be >= 1");
    if (!a.Get("at")) return absl::InvalidArgumentError("--waypoint needs --at X,Y");
    ASSIGN_OR_RETURN(auto at, ParsePair("at", *a.Get("at")));
    request.mutable_progress()->set_waypoint(static_cast<int32_t>(*waypoint));
    request.mutable_progress()->mutable_position()->set_x(at.first);
    request.mutable_progress()->mutable_position()->set_y(at.second);
  } else {
    request.mutable_progress()->set_distance_m(*distance);
  }
  RETURN_IF_ERROR(ParseObstacleFlags(a, request.mutable_obstacles()));
  ASSIGN_OR_RETURN(v1::ReplanMethod method, ParseMethodFlag(a));
  request.set_method(method);
  ASSIGN_OR_RETURN(std::optional<int64_t> seed, a.GetInt("seed"));
  if (seed) request.set_seed(static_cast<uint32_t>(*seed));
  ASSIGN_OR_RETURN(std::optional<absl::Duration> timeout, ParseDeadlineFlag(a));
  ASSIGN_OR_RETURN(Connection server,
                   ConnectionFromArgs(a, a.Get("server").value_or(kDefaultServer)));
  return WriteReply(
      a, server.target,
      RemotePlanner::Connect(server)->Replan(request, timeout, a.Get("map-id").value_or("")));
}

constexpr char kResumeUsage[] =
    "usage: covplan resume --plan-id P --at X,Y[,THETA]\n"
    "                      [--waypoint K --stopped-at X,Y | --distance D]\n"
    "                      [--obstacle AREA]... [--obstacle-cell ROW,COL]... [--obstacle-point "
    "X,Y]...\n"
    "                      [--method auto|ilp1|ilp2|greedy_detour|full] [--seed N]\n"
    "                      [--server HOST:PORT] [--deadline-ms D] [--out plan.json]\n"
    "                      [--tls-ca PEM] [--tls-cert PEM --tls-key PEM] [--token T | --token-file "
    "F]\n"
    "Continues plan P after an interruption (battery swap, e-stop, restart): the robot\n"
    "is now at --at (e.g. on its dock); the new plan drives back to where it stopped and\n"
    "on over what it had not covered. Where it stopped: --waypoint K --stopped-at X,Y\n"
    "(the segment and the position on it) or --distance D metres along the path; without\n"
    "either, the last progress the server recorded for P (from Drive sessions, Replan\n"
    "and Resume calls), else the plan's start. Obstacles seen since may be added as for\n"
    "`covplan replan`. The server defaults to 127.0.0.1:50051.\n";

absl::Status RunResume(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(
      ParsedArgs a,
      ParseArgs(args,
                WithConnectionFlags({"plan-id", "at", "waypoint", "stopped-at", "distance",
                                     "method", "seed", "server", "deadline-ms", "out"}),
                {}, {"obstacle", "obstacle-cell", "obstacle-point"}));
  v1::ResumeRequest request;
  if (!a.Get("plan-id")) return absl::InvalidArgumentError("--plan-id P is required");
  request.set_plan_id(*a.Get("plan-id"));
  if (!a.Get("at"))
    return absl::InvalidArgumentError("--at X,Y[,THETA] (where the robot is now) is required");
  {
    std::vector<std::string> parts = absl::StrSplit(*a.Get("at"), ',');
    double v[3] = {0, 0, 0};
    bool ok = parts.size() == 2 || parts.size() == 3;
    for (size_t i = 0; ok && i < parts.size(); ++i) ok = absl::SimpleAtod(parts[i], &v[i]);
    if (!ok)
      return absl::InvalidArgumentError(
          absl::StrCat("--at must be X,Y or X,Y,THETA, got '", *a.Get("at"), "'"));
    request.mutable_pose()->set_x(v[0]);
    request.mutable_pose()->set_y(v[1]);
    request.mutable_pose()->set_theta(v[2]);
  }
  ASSIGN_OR_RETURN(std::optional<int64_t> waypoint, a.GetInt("waypoint"));
  ASSIGN_OR_RETURN(std::optional<double> distance, a.GetDouble("distance"));
  if (waypoint && distance)
    return absl::InvalidArgumentError("give --waypoint K with --stopped-at X,Y, or --distance D");
  if (waypoint) {
    if (*waypoint < 1 || *waypoint > INT32_MAX)
      return absl::InvalidArgumentError("--waypoint must be >= 1");
    if (!a.Get("stopped-at"))
      return absl::InvalidArgumentError("--waypoint needs --stopped-at X,Y");
    ASSIGN_OR_RETURN(auto at, ParsePair("stopped-at", *a.Get("stopped-at")));
    request.mutable_progress()->set_waypoint(static_cast<int32_t>(*waypoint));
    request.mutable_progress()->mutable_position()->set_x(at.first);
    request.mutable_progress()->mutable_position()->set_y(at.second);
  } else if (distance) {
    request.mutable_progress()->set_distance_m(*distance);
  } else if (a.Get("stopped-at")) {
    return absl::InvalidArgumentError("--stopped-at needs --waypoint K");
  }
  RETURN_IF_ERROR(ParseObstacleFlags(a, request.mutable_obstacles()));
  ASSIGN_OR_RETURN(v1::ReplanMethod method, ParseMethodFlag(a));
  request.set_method(method);
  ASSIGN_OR_RETURN(std::optional<int64_t> seed, a.GetInt("seed"));
  if (seed) request.set_seed(static_cast<uint32_t>(*seed));
  ASSIGN_OR_RETURN(std::optional<absl::Duration> timeout, ParseDeadlineFlag(a));
  ASSIGN_OR_RETURN(Connection server,
                   ConnectionFromArgs(a, a.Get("server").value_or(kDefaultServer)));
  return WriteReply(a, server.target, RemotePlanner::Connect(server)->Resume(request, timeout));
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
      "%s"
      "mission    %d cells swept by earlier plans, %d to sweep now, %d cut off and %d occupied by "
      "new obstacles%s\n"
      "duration   %.1f s estimated for the rest\n"
      "timings    %.1f ms: ranks %.1f, transitions %.1f, tour %.1f ms\n",
      r.plan().plan_id(), s.method(), s.newly_blocked_cells(), s.num_encounters(), detours,
      s.replanned_encounter(), s.time_to_encounter_s(), s.new_ranks(), s.rank_budget(),
      s.kept_ranks(), s.kept_path_pieces(), s.kept_path_m(), s.covered_cells_before(),
      s.remaining_cells(), s.newly_unreachable_cells(),
      s.complete() ? "" : " (NOT complete: cells were cut off)",
      s.progress_source().empty()
          ? std::string()
          : absl::StrFormat("resumed    from where it stopped (%s), %.1f m back to it\n",
                            s.progress_source(), s.rejoin_m()),
      r.plan().stats().mission_covered_cells(), r.plan().stats().free_cells(),
      r.plan().stats().mission_cut_off_cells(), r.plan().stats().mission_obstructed_cells(),
      r.plan().stats().mission_cut_off_cells() > 0 ? " (the job cannot be completed as mapped)"
                                                   : "",
      r.plan().stats().estimated_duration_s(), s.total_ms(), s.rank_replan_ms(), s.transitions_ms(),
      s.tour_ms());
}

int RunReplanCommand(const std::vector<std::string>& args) {
  return RunSubcommand("replan", kUsage, args, &Run);
}

int RunResumeCommand(const std::vector<std::string>& args) {
  return RunSubcommand("resume", kResumeUsage, args, &RunResume);
}

}  // namespace covplan
