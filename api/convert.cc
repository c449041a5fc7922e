#include "api/convert.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "absl/numeric/int128.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api/convert_stc.h"
#include "api/digest.h"
#include "api/geojson.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/boustrophedon/boustrophedon_planner.h"
#include "planner/common/status_macros.h"
#include "planner/grid/grid.h"
#include "planner/grid/map_io.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/rank.h"

namespace covplan {
namespace {

absl::Status Annotate(const absl::Status& status, absl::string_view prefix) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

bool IsPositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

absl::Status CheckPositive(double v, absl::string_view field, absl::string_view unit) {
  if (IsPositiveFinite(v)) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrFormat("%s must be a positive, finite number of %s (got %g)", field, unit, v));
}

absl::Status CheckFinite(double v, absl::string_view field) {
  if (std::isfinite(v)) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrFormat("%s must be finite (got %g)", field, v));
}

// Width and height from an image header, if the header is complete enough to
// read them; decoding proper is left to the map reader, which reports errors.
std::optional<std::pair<int64_t, int64_t>> SniffDimensions(const std::string& bytes) {
  switch (DetectImageFormat(bytes)) {
    case ImageFormat::kPng: {
      if (bytes.size() < 24) return std::nullopt;
      auto be32 = [&](size_t at) {
        int64_t v = 0;
        for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<uint8_t>(bytes[at + i]);
        return v;
      };
      return std::make_pair(be32(16), be32(20));
    }
    case ImageFormat::kPgm: {
      size_t pos = 2;
      int64_t values[2] = {0, 0};
      for (int64_t& value : values) {
        while (pos < bytes.size()) {  // whitespace and comments
          if (std::isspace(static_cast<unsigned char>(bytes[pos]))) {
            ++pos;
          } else if (bytes[pos] == '#') {
            while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
          } else {
            break;
          }
        }
        int digits = 0;
        while (pos < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[pos])) &&
               digits < 12) {
          value = value * 10 + (bytes[pos++] - '0');
          ++digits;
        }
        if (digits == 0) return std::nullopt;
      }
      return std::make_pair(values[0], values[1]);
    }
    case ImageFormat::kUnknown:
      break;
  }
  return std::nullopt;
}

void AppendField(std::string* out, absl::string_view name, absl::string_view value) {
  absl::StrAppend(out, name, ":", value.size(), ":", value, "\n");
}

absl::StatusOr<std::string> ReadFile(const std::string& path, int64_t max_bytes) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return absl::NotFoundError(absl::StrCat("map file not found: ", path));
  }
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return absl::InvalidArgumentError(absl::StrCat("cannot read ", path, ": ", ec.message()));
  if (static_cast<int64_t>(size) > max_bytes) {
    return absl::InvalidArgumentError(absl::StrFormat("%s is %d bytes, above the limit of %d bytes",
                                                      path, static_cast<int64_t>(size), max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::InvalidArgumentError(absl::StrCat("cannot open ", path));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

}  // namespace

std::string ComputeMapId(const v1::Map& map) {
  if (map.source_case() == v1::Map::kPolygons) {
    std::string canonical = "covplan.map.v1.polygons\n";
    const v1::PolygonMap& pm = map.polygons();
    AppendField(&canonical, "resolution", absl::StrFormat("%a", pm.resolution()));
    auto ring = [&](const char* name, const v1::Ring& r) {
      std::string pts;
      for (const v1::Point2& p : r.points()) absl::StrAppendFormat(&pts, "%a,%a;", p.x(), p.y());
      AppendField(&canonical, name, pts);
    };
    for (const v1::Polygon& p : pm.polygons()) {
      ring("outer", p.outer());
      for (const v1::Ring& h : p.holes()) ring("hole", h);
    }
    return Sha256Hex(canonical);
  }
  std::string canonical = "covplan.map.v1\n";
  const v1::RasterMap& r = map.raster();
  AppendField(&canonical, "image", r.image());
  AppendField(&canonical, "yaml", r.yaml());
  // %a prints doubles exactly, so equal values give equal ids.
  if (r.has_resolution())
    AppendField(&canonical, "resolution", absl::StrFormat("%a", r.resolution()));
  if (r.has_origin_x_m())
    AppendField(&canonical, "origin_x_m", absl::StrFormat("%a", r.origin_x_m()));
  if (r.has_origin_y_m())
    AppendField(&canonical, "origin_y_m", absl::StrFormat("%a", r.origin_y_m()));
  if (r.has_negate()) AppendField(&canonical, "negate", r.negate() ? "1" : "0");
  if (r.has_occupied_thresh()) {
    AppendField(&canonical, "occupied_thresh", absl::StrFormat("%a", r.occupied_thresh()));
  }
  if (r.has_free_thresh())
    AppendField(&canonical, "free_thresh", absl::StrFormat("%a", r.free_thresh()));

  return Sha256Hex(canonical);
}

absl::Status ValidateMapId(absl::string_view map_id) {
  bool ok = map_id.size() == 64;
  for (char c : map_id)
    ok = ok && (std::isdigit(static_cast<unsigned char>(c)) || (c >= 'a' && c <= 'f'));
  if (ok) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(
      "map_id '", map_id.substr(0, 80), "' is malformed: expected 64 lowercase hex digits"));
}

absl::StatusOr<OccupancyMap> MapFromProto(const v1::Map& map, const EngineLimits& limits) {
  if (map.source_case() != v1::Map::kRaster) {
    return absl::InvalidArgumentError(map.source_case() == v1::Map::kPolygons
                                          ? "map.polygons is a vector map, not a raster"
                                          : "map has no source: set map.raster or map.polygons");
  }
  const v1::RasterMap& r = map.raster();
  if (r.image().empty()) return absl::InvalidArgumentError("map.raster.image is empty");
  if (static_cast<int64_t>(r.image().size()) > limits.max_image_bytes) {
    return absl::InvalidArgumentError(
        absl::StrFormat("map.raster.image is too large: %d bytes, above the limit of %d bytes",
                        static_cast<int64_t>(r.image().size()), limits.max_image_bytes));
  }
  if (DetectImageFormat(r.image()) == ImageFormat::kUnknown) {
    return absl::InvalidArgumentError(
        "map.raster.image is neither a PGM (P2/P5) nor a PNG image (corrupt or unsupported data)");
  }
  if (auto dims = SniffDimensions(r.image())) {
    // A header may claim any size: the product of two claims (each below 2^63)
    // is taken in 128 bits, so it never overflows.
    const absl::int128 pixels = absl::int128(dims->first) * dims->second;
    if (pixels > limits.max_map_pixels) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "map.raster.image is too large: %d x %d = %d pixels, above the limit of %d pixels",
          dims->first, dims->second, pixels, limits.max_map_pixels));
    }
  }

  MapLoadOptions options;
  if (!r.yaml().empty()) {
    absl::StatusOr<MapYaml> parsed = ParseMapYaml(r.yaml(), options);
    if (!parsed.ok()) return Annotate(parsed.status(), "map.raster.yaml: ");
    options = parsed->options;  // its `image:` is ignored: the bytes are the image
  } else if (!r.has_resolution()) {
    return absl::InvalidArgumentError(
        "map.raster.resolution is required for a bare image (no YAML given)");
  }
  if (r.has_resolution()) {
    options.resolution = r.resolution();
    options.override_resolution = true;
  }
  if (r.has_origin_x_m()) options.origin.x = r.origin_x_m();
  if (r.has_origin_y_m()) options.origin.y = r.origin_y_m();
  if (r.has_negate()) options.negate = r.negate();
  if (r.has_occupied_thresh()) options.occupied_thresh = r.occupied_thresh();
  if (r.has_free_thresh()) options.free_thresh = r.free_thresh();
  options.max_pixels = limits.max_map_pixels;
  options.max_file_bytes = limits.max_image_bytes;

  RETURN_IF_ERROR(CheckPositive(options.resolution, "map resolution", "metres per pixel"));
  RETURN_IF_ERROR(CheckFinite(options.origin.x, "map origin x"));
  RETURN_IF_ERROR(CheckFinite(options.origin.y, "map origin y"));
  for (auto [value, name] : {std::pair{options.occupied_thresh, "occupied_thresh"},
                             std::pair{options.free_thresh, "free_thresh"}}) {
    if (!std::isfinite(value) || value < 0.0 || value > 1.0) {
      return absl::InvalidArgumentError(
          absl::StrFormat("map %s must be in [0, 1] (got %g)", name, value));
    }
  }
  if (options.free_thresh >= options.occupied_thresh) {
    return absl::InvalidArgumentError(
        absl::StrFormat("map free_thresh (%g) must be below occupied_thresh (%g)",
                        options.free_thresh, options.occupied_thresh));
  }

  absl::StatusOr<OccupancyMap> decoded = DecodeMapImage(r.image(), options);
  if (!decoded.ok()) return Annotate(decoded.status(), "map.raster.image: ");
  if (decoded->width() <= 0 || decoded->height() <= 0) {
    return absl::InvalidArgumentError("map.raster.image has no pixels");
  }
  if (decoded->CountFree() == 0) {
    return absl::InvalidArgumentError(
        "map has no free pixel: nothing to cover (check negate and the thresholds)");
  }
  return decoded;
}

namespace {

// OARP's options: the nested message, or the top-level fields of older
// clients; `local` adds what the proto does not carry.
absl::StatusOr<std::shared_ptr<const OarpOptions>> OarpOptionsFromProto(
    const v1::PlanRequest& request, const LocalPlanOptions& local) {
  const bool nested = request.has_oarp();
  const char* prefix = nested ? "oarp." : "";
  const v1::PartitionSolver partition =
      nested ? request.oarp().partition_solver() : request.partition_solver();
  const v1::TourSolver tour = nested ? request.oarp().tour_solver() : request.tour_solver();
  auto oarp = std::make_shared<OarpOptions>();
  switch (partition) {
    case v1::PARTITION_SOLVER_UNSPECIFIED:
      break;  // the planner's default (push-relabel)
    case v1::MINCUT:
      oarp->partition_solver = PartitionSolver::kMinCut;
      break;
    case v1::LP:
      oarp->partition_solver = PartitionSolver::kLp;
      break;
    case v1::MATCHING:
      oarp->partition_solver = PartitionSolver::kMatching;
      break;
    case v1::PUSH_RELABEL:
      oarp->partition_solver = PartitionSolver::kPushRelabel;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat(prefix, "partition_solver: unknown value ", static_cast<int>(partition)));
  }
  switch (tour) {
    case v1::TOUR_SOLVER_UNSPECIFIED:
    case v1::GTSP:
      oarp->tour_solver = TourSolver::kGtsp;
      break;
    case v1::GREEDY:
      oarp->tour_solver = TourSolver::kGreedy;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat(prefix, "tour_solver: unknown value ", static_cast<int>(tour)));
  }
  if (local.oarp_tour_effort) oarp->tour_effort = *local.oarp_tour_effort;
  return oarp;
}

absl::StatusOr<std::shared_ptr<const BoustrophedonOptions>> BoustrophedonOptionsFromProto(
    const v1::PlanRequest& request) {
  const v1::BoustrophedonOptions& b = request.boustrophedon();
  auto options_b = std::make_shared<BoustrophedonOptions>();
  switch (b.sweep_axis()) {
    case v1::SWEEP_AXIS_UNSPECIFIED:
    case v1::SWEEP_AXIS_AUTO:
      options_b->sweep_axis = BoustrophedonAxis::kAuto;
      break;
    case v1::SWEEP_AXIS_VERTICAL:
      options_b->sweep_axis = BoustrophedonAxis::kVertical;
      break;
    case v1::SWEEP_AXIS_HORIZONTAL:
      options_b->sweep_axis = BoustrophedonAxis::kHorizontal;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat("boustrophedon.sweep_axis: unknown value ",
                                                     static_cast<int>(b.sweep_axis())));
  }
  switch (b.tour_solver()) {
    case v1::TOUR_SOLVER_UNSPECIFIED:
    case v1::GTSP:
      options_b->tour_solver = TourSolver::kGtsp;
      break;
    case v1::GREEDY:
      options_b->tour_solver = TourSolver::kGreedy;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat("boustrophedon.tour_solver: unknown value ",
                                                     static_cast<int>(b.tour_solver())));
  }
  return options_b;
}

absl::StatusOr<BatteryOptions> BatteryFromProto(const v1::PlanRequest& request) {
  const v1::Battery& b = request.battery();
  if (!b.has_station()) return absl::InvalidArgumentError("battery.station is required");
  BatteryOptions battery;
  battery.capacity = b.capacity();
  battery.reserve = b.reserve();
  battery.station = Pose2{b.station().x(), b.station().y(), b.station().theta()};
  if (b.energy().has_per_metre()) battery.energy.per_metre = b.energy().per_metre();
  battery.energy.per_turn = b.energy().per_turn();
  battery.energy.per_second = b.energy().per_second();
  battery.interruptible_units = b.interruptible_units();
  battery.atomic_units.assign(b.atomic_units().begin(), b.atomic_units().end());
  RETURN_IF_ERROR(battery.Validate());
  return battery;
}

}  // namespace

absl::StatusOr<PlanRequest> PlanRequestFromProto(const v1::PlanRequest& request,
                                                 const LocalPlanOptions& local) {
  PlanRequest out;
  out.planner = request.planner().empty() ? std::string(kDefaultPlanner) : request.planner();
  if (out.planner.size() > 64) {
    return absl::InvalidArgumentError("planner: name longer than 64 characters");
  }
  CommonOptions& options = out.common;
  // Field values are copied as given; CommonOptions::Validate (and the
  // planner's options) check them and name the proto field in the message.
  const v1::RobotModel& robot = request.robot();
  options.robot.tool_width_m = robot.tool_width_m();
  if (robot.has_max_speed_mps()) options.robot.max_speed_mps = robot.max_speed_mps();
  if (robot.has_acceleration_mps2()) options.robot.acceleration_mps2 = robot.acceleration_mps2();
  if (robot.has_turn_rate_deg_s()) options.robot.turn_rate_deg_s = robot.turn_rate_deg_s();
  if (robot.has_start())
    options.robot.start = Pose2{robot.start().x(), robot.start().y(), robot.start().theta()};
  if (robot.has_end())
    options.robot.end = Pose2{robot.end().x(), robot.end().y(), robot.end().theta()};

  if (request.planner_options_case() == v1::PlanRequest::kOarp || out.planner == "oarp") {
    if (request.planner_options_case() != v1::PlanRequest::kOarp &&
        request.planner_options_case() != v1::PlanRequest::PLANNER_OPTIONS_NOT_SET) {
      return absl::InvalidArgumentError("planner_options: planner 'oarp' takes the oarp options");
    }
    ASSIGN_OR_RETURN(out.options, OarpOptionsFromProto(request, local));
  } else if (request.planner_options_case() == v1::PlanRequest::kBoustrophedon ||
             out.planner == "boustrophedon") {
    if (request.planner_options_case() != v1::PlanRequest::kBoustrophedon &&
        request.planner_options_case() != v1::PlanRequest::PLANNER_OPTIONS_NOT_SET) {
      return absl::InvalidArgumentError(
          "planner_options: planner 'boustrophedon' takes the boustrophedon options");
    }
    ASSIGN_OR_RETURN(out.options, BoustrophedonOptionsFromProto(request));
  }
  if (request.has_battery()) {
    ASSIGN_OR_RETURN(out.battery, BatteryFromProto(request));
  }
  if (request.planner_options_case() == v1::PlanRequest::kStc) {
    if (out.planner != "stc") {
      return absl::InvalidArgumentError(absl::StrCat(
          "planner_options: the stc options are for planner 'stc', not '", out.planner, "'"));
    }
    ASSIGN_OR_RETURN(out.options, StcOptionsFromProto(request.stc()));
  }
  // 0 means "default" for both (proto3 scalars have no presence).
  if (request.time_limit_s() != 0.0) options.time_limit_s = request.time_limit_s();
  options.seed = request.seed();
  out.improve_remembered = request.improve_remembered();
  if (request.min_free_fraction() != 0.0) options.min_free_fraction = request.min_free_fraction();
  out.regions = PolygonsFromProto(request.regions());
  out.no_go = PolygonsFromProto(request.no_go());
  RETURN_IF_ERROR(options.Validate());
  return out;
}

absl::StatusOr<SiteMap> SiteFromProto(const v1::Map& map, const EngineLimits& limits) {
  if (map.source_case() == v1::Map::kPolygons) {
    const v1::PolygonMap& pm = map.polygons();
    if (pm.polygons().empty()) {
      return absl::InvalidArgumentError("map.polygons.polygons is empty: no free space");
    }
    AreaLimits area_limits;
    area_limits.max_vertices = limits.max_area_vertices;
    ASSIGN_OR_RETURN(Area area,
                     Area::Create(PolygonsFromProto(pm.polygons()), "map.polygons", area_limits));
    double resolution = pm.resolution();
    if (resolution == 0.0) resolution = 0.05;
    if (!std::isfinite(resolution) || resolution < 1e-3 || resolution > 10.0) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "map.polygons.resolution must be between 0.001 and 10 m (got %g)", resolution));
    }
    return SiteFromPolygons(std::make_shared<const Area>(std::move(area)), resolution,
                            limits.max_map_pixels);
  }
  ASSIGN_OR_RETURN(OccupancyMap raster, MapFromProto(map, limits));
  SiteMap site;
  site.raster = std::make_shared<const OccupancyMap>(std::move(raster));
  return site;
}

v1::MapInfo MapInfoFor(const OccupancyMap& map, const std::string& map_id) {
  v1::MapInfo info;
  info.set_map_id(map_id);
  info.set_width_px(map.width());
  info.set_height_px(map.height());
  info.set_resolution(map.resolution());
  info.set_origin_x_m(map.origin().x);
  info.set_origin_y_m(map.origin().y);
  info.set_free_area_m2(map.FreeAreaM2());
  return info;
}

v1::MapInfo MapInfoFor(const SiteMap& site, const std::string& map_id) {
  v1::MapInfo info = MapInfoFor(*site.raster, map_id);
  if (site.polygons != nullptr) info.set_free_area_m2(site.polygons->AreaM2());
  return info;
}

absl::StatusOr<v1::Map> MapProtoFromFile(const std::string& path, const MapFileOverrides& overrides,
                                         const EngineLimits& limits) {
  v1::Map map;
  std::filesystem::path file(path);
  const std::string ext = absl::AsciiStrToLower(file.extension().string());
  if (ext == ".geojson" || ext == ".json") {
    ASSIGN_OR_RETURN(std::string text, ReadFile(path, 16 << 20));
    ASSIGN_OR_RETURN(std::vector<PolygonInput> polygons, ParseGeoJsonPolygons(text, path));
    v1::PolygonMap* pm = map.mutable_polygons();
    PolygonsToProto(polygons, pm->mutable_polygons());
    if (overrides.resolution) pm->set_resolution(*overrides.resolution);
    return map;
  }
  v1::RasterMap* raster = map.mutable_raster();
  if (ext == ".yaml" || ext == ".yml") {
    ASSIGN_OR_RETURN(std::string yaml, ReadFile(path, 1 << 20));
    absl::StatusOr<MapYaml> parsed = ParseMapYaml(yaml, MapLoadOptions());
    if (!parsed.ok()) return Annotate(parsed.status(), absl::StrCat(path, ": "));
    if (parsed->image.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": the YAML names no image"));
    }
    std::filesystem::path image(parsed->image);
    if (image.is_relative()) image = file.parent_path() / image;
    ASSIGN_OR_RETURN(*raster->mutable_image(), ReadFile(image.string(), limits.max_image_bytes));
    raster->set_yaml(std::move(yaml));
  } else {
    if (!overrides.resolution) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, " is a bare image: --resolution M (metres per pixel) is required"));
    }
    ASSIGN_OR_RETURN(*raster->mutable_image(), ReadFile(path, limits.max_image_bytes));
  }
  if (overrides.resolution) raster->set_resolution(*overrides.resolution);
  if (overrides.negate) raster->set_negate(*overrides.negate);
  if (overrides.occupied_thresh) raster->set_occupied_thresh(*overrides.occupied_thresh);
  if (overrides.free_thresh) raster->set_free_thresh(*overrides.free_thresh);
  return map;
}

}  // namespace covplan
