#include "client/plan_exports.h"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "client/geo_site.h"
#include "planner/common/status_macros.h"

namespace covplan {

std::set<std::string> PlanExportFlags() {
  return {"out-geojson", "out-csv", "out-nav-path", "frame-id", "nav-stamp"};
}

absl::StatusOr<PlanExports> PlanExportsFromFlags(const ParsedArgs& a) {
  PlanExports e;
  e.geojson = a.Get("out-geojson");
  e.csv = a.Get("out-csv");
  e.nav_path = a.Get("out-nav-path");
  if (auto frame = a.Get("frame-id")) e.nav.frame_id = *frame;
  ASSIGN_OR_RETURN(std::optional<double> stamp, a.GetDouble("nav-stamp"));
  if (stamp) {
    if (!std::isfinite(*stamp) || *stamp < 0.0) {
      return absl::InvalidArgumentError("--nav-stamp must be Unix seconds >= 0");
    }
    e.nav.start_stamp_s = *stamp;
  }
  if (!e.nav_path && (a.Get("frame-id") || stamp)) {
    return absl::InvalidArgumentError("--frame-id and --nav-stamp need --out-nav-path");
  }
  if (e.nav.frame_id.empty()) return absl::InvalidArgumentError("--frame-id must not be empty");
  return e;
}

absl::Status WritePlanExports(const PlanExports& exports, const v1::PlanResponse& plan,
                              const ExportFrame& frame) {
  if (exports.geojson) {
    ASSIGN_OR_RETURN(std::string text, PlanToGeoJson(plan, frame));
    RETURN_IF_ERROR(WriteTextFile(*exports.geojson, text));
  }
  if (exports.csv) {
    ASSIGN_OR_RETURN(std::string text, PlanToCsv(plan, frame));
    RETURN_IF_ERROR(WriteTextFile(*exports.csv, text));
  }
  if (exports.nav_path) {
    ASSIGN_OR_RETURN(std::string text, PlanToNavPath(plan, exports.nav));
    RETURN_IF_ERROR(WriteTextFile(*exports.nav_path, text));
  }
  return absl::OkStatus();
}

namespace {

constexpr char kExportUsage[] =
    "usage: covplan export --plan FILE [--robot ID] [--out-geojson FILE] [--out-csv FILE]\n"
    "                      [--out-nav-path FILE [--frame-id ID] [--nav-stamp UNIX_S]]\n"
    "                      [--map MAP.geojson --crs CRS]\n"
    "FILE is a plan.json (covplan plan --out, a GetPlan reply) or a fleet's JSON\n"
    "(covplan plan --robot ... --out), then --robot names the robot whose plan to export.\n"
    "--map and --crs: the plan was made with covplan plan --crs CRS on that map; the\n"
    "GeoJSON and CSV are then written in CRS.\n";

// The plan in `text`: a PlanResponse, or robot `robot`'s plan of a fleet JSON.
absl::StatusOr<v1::PlanResponse> PlanFromJsonText(const std::string& text,
                                                  const std::optional<std::string>& robot,
                                                  const std::string& source) {
  google::protobuf::util::JsonParseOptions lenient;
  lenient.ignore_unknown_fields = true;
  google::protobuf::Struct document;
  if (!google::protobuf::util::JsonStringToMessage(text, &document).ok())
    return absl::InvalidArgumentError(absl::StrCat(source, ": not valid JSON"));
  std::string plan_json = text;
  const auto robots = document.fields().find("robots");
  if (robots != document.fields().end()) {
    if (!robot)
      return absl::InvalidArgumentError(source + " is a fleet: name a robot with --robot");
    const google::protobuf::Value* found = nullptr;
    for (const google::protobuf::Value& r : robots->second.list_value().values()) {
      const auto& fields = r.struct_value().fields();
      const auto id = fields.find("id");
      const auto plan = fields.find("plan");
      if (id != fields.end() && id->second.string_value() == *robot && plan != fields.end())
        found = &plan->second;
    }
    if (found == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat(source, " has no robot '", *robot, "'"));
    }
    plan_json.clear();
    if (!google::protobuf::util::MessageToJsonString(found->struct_value(), &plan_json).ok())
      return absl::InternalError("re-printing the robot's plan failed");
  } else if (robot) {
    return absl::InvalidArgumentError(source + " is a single plan: drop --robot");
  }
  v1::PlanResponse plan;
  const auto status = google::protobuf::util::JsonStringToMessage(plan_json, &plan, lenient);
  if (!status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": not a plan: ", std::string(status.message())));
  }
  if (plan.path_size() == 0) return absl::InvalidArgumentError(source + ": the plan has no path");
  return plan;
}

absl::Status RunExport(const std::vector<std::string>& args) {
  std::set<std::string> flags = PlanExportFlags();
  flags.insert({"plan", "robot", "map", "crs"});
  ASSIGN_OR_RETURN(ParsedArgs a, ParseArgs(args, flags, {}, {}));
  const std::optional<std::string> path = a.Get("plan");
  if (!path) return absl::InvalidArgumentError("--plan FILE is required");
  ASSIGN_OR_RETURN(PlanExports exports, PlanExportsFromFlags(a));
  if (!exports.any()) {
    return absl::InvalidArgumentError("name an export: --out-geojson, --out-csv or --out-nav-path");
  }
  ASSIGN_OR_RETURN(std::string text, ReadFlagFile("plan", *path));
  ASSIGN_OR_RETURN(v1::PlanResponse plan, PlanFromJsonText(text, a.Get("robot"), *path));
  if (a.Get("crs").has_value() != a.Get("map").has_value())
    return absl::InvalidArgumentError("--crs and --map go together (the site's frame)");
  std::optional<GeoFrame> frame;
  if (auto map_path = a.Get("map")) {
    ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(*map_path, {}, EngineLimits()));
    v1::PlanRequest unused;
    ASSIGN_OR_RETURN(frame, ProjectIntoSite(a.Get("crs"), &map, &unused));
  }
  return WritePlanExports(exports, plan, ExportFrameOf(frame));
}

}  // namespace

int RunExportCommand(const std::vector<std::string>& args) {
  return RunSubcommand("export", kExportUsage, args, &RunExport);
}

}  // namespace covplan
