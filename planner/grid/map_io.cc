// Map files: ROS map_server YAML (+ the image it names), bare images, and
// writing a map back as YAML + PGM. Image decoding is in image_decode.cc.
#include "planner/grid/map_io.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

namespace fs = std::filesystem;

// A map_server YAML is a handful of lines; anything bigger is not one.
constexpr size_t kMaxYamlBytes = 1 << 20;

// ---------------------------------------------------------------- YAML

absl::StatusOr<double> YamlNumber(const YAML::Node& node, const char* key) {
  double v = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "'", key, "' must be a number",
        node.IsScalar() ? absl::StrCat(", got '", node.Scalar(), "'") : std::string()));
  }
  return v;
}

absl::StatusOr<bool> YamlNegate(const YAML::Node& node) {
  if (node.IsScalar()) {
    const std::string& s = node.Scalar();
    if (s == "0") return false;
    if (s == "1") return true;
    bool b = false;
    if (YAML::convert<bool>::decode(node, b)) return b;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("'negate' must be 0, 1, true or false",
                   node.IsScalar() ? absl::StrCat(", got '", node.Scalar(), "'") : std::string()));
}

absl::StatusOr<MapYaml> ParseMapYamlRoot(const YAML::Node& root, const MapLoadOptions& defaults) {
  if (!root.IsMap()) {
    return absl::InvalidArgumentError(
        "map YAML must be a mapping with at least the keys 'image' and 'resolution'");
  }
  MapYaml out;
  out.options = defaults;

  const YAML::Node image = root["image"];
  if (!image.IsDefined() || image.IsNull()) {
    return absl::InvalidArgumentError("map YAML is missing the required key 'image'");
  }
  if (!image.IsScalar() || image.Scalar().empty()) {
    return absl::InvalidArgumentError("'image' must be the name of the map image file");
  }
  out.image = image.Scalar();

  const YAML::Node resolution = root["resolution"];
  if (!resolution.IsDefined() || resolution.IsNull()) {
    if (!defaults.override_resolution) {
      return absl::InvalidArgumentError("map YAML is missing the required key 'resolution'");
    }
  } else {
    ASSIGN_OR_RETURN(const double res, YamlNumber(resolution, "resolution"));
    if (!defaults.override_resolution) out.options.resolution = res;
  }

  if (const YAML::Node origin = root["origin"]; origin.IsDefined() && !origin.IsNull()) {
    if (!origin.IsSequence() || (origin.size() != 2 && origin.size() != 3)) {
      return absl::InvalidArgumentError("'origin' must be a list [x, y, yaw]");
    }
    ASSIGN_OR_RETURN(out.options.origin.x, YamlNumber(origin[0], "origin x"));
    ASSIGN_OR_RETURN(out.options.origin.y, YamlNumber(origin[1], "origin y"));
    if (origin.size() == 3) {
      ASSIGN_OR_RETURN(const double yaw, YamlNumber(origin[2], "origin yaw"));
      if (yaw != 0.0) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "rotated maps are not supported (origin yaw = %g); rotate the image instead", yaw));
      }
    }
  }
  if (const YAML::Node negate = root["negate"]; negate.IsDefined() && !negate.IsNull()) {
    ASSIGN_OR_RETURN(out.options.negate, YamlNegate(negate));
  }
  if (const YAML::Node t = root["occupied_thresh"]; t.IsDefined() && !t.IsNull()) {
    ASSIGN_OR_RETURN(out.options.occupied_thresh, YamlNumber(t, "occupied_thresh"));
  }
  if (const YAML::Node t = root["free_thresh"]; t.IsDefined() && !t.IsNull()) {
    ASSIGN_OR_RETURN(out.options.free_thresh, YamlNumber(t, "free_thresh"));
  }
  if (const YAML::Node mode = root["mode"]; mode.IsDefined() && !mode.IsNull()) {
    const std::string m = mode.IsScalar() ? absl::AsciiStrToLower(mode.Scalar()) : "";
    if (m != "trinary") {
      return absl::InvalidArgumentError(
          absl::StrCat("map mode '", mode.IsScalar() ? mode.Scalar() : "?",
                       "' is not supported: only 'trinary' maps (free / occupied / unknown) are"));
    }
  }
  RETURN_IF_ERROR(out.options.Validate());
  return out;
}

// ---------------------------------------------------------------- files

absl::Status WithPrefix(const absl::Status& s, absl::string_view prefix) {
  if (s.ok()) return s;
  return absl::Status(s.code(), absl::StrCat(prefix, ": ", s.message()));
}

absl::StatusOr<std::string> ReadFile(const fs::path& path, int64_t max_bytes) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) return absl::NotFoundError(absl::StrCat("file not found: ", path.string()));
  if (fs::is_directory(st)) {
    return absl::InvalidArgumentError(
        absl::StrCat(path.string(), " is a directory, not a map file"));
  }
  const uintmax_t size = fs::file_size(path, ec);
  if (ec)
    return absl::InvalidArgumentError(
        absl::StrCat("cannot read ", path.string(), ": ", ec.message()));
  if (size > static_cast<uintmax_t>(max_bytes)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s is %d bytes, above the limit max_file_bytes = %d", path.string(), size, max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::ErrnoToStatus(errno, absl::StrCat("cannot open ", path.string()));
  std::string data(size, '\0');
  in.read(data.data(), static_cast<std::streamsize>(size));
  if (static_cast<uintmax_t>(in.gcount()) != size) {
    return absl::DataLossError(absl::StrCat("short read from ", path.string()));
  }
  return data;
}

absl::Status WriteFile(const fs::path& path, std::string_view data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return absl::ErrnoToStatus(errno, absl::StrCat("cannot create ", path.string()));
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out) return absl::ErrnoToStatus(errno, absl::StrCat("cannot write ", path.string()));
  return absl::OkStatus();
}

// Shortest of %.15g / %.17g that reads back as the same double.
std::string ExactDouble(double v) {
  std::string s = absl::StrFormat("%.15g", v);
  if (std::strtod(s.c_str(), nullptr) != v) s = absl::StrFormat("%.17g", v);
  return s;
}

// A YAML double-quoted scalar.
std::string YamlQuote(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      absl::StrAppend(&out, "\\", std::string(1, ch));
    } else if (u < 0x20 || u == 0x7f) {
      absl::StrAppend(&out, absl::StrFormat("\\x%02x", u));
    } else {
      out.push_back(ch);
    }
  }
  out.push_back('"');
  return out;
}

bool HasYamlExtension(const fs::path& path) {
  const std::string ext = absl::AsciiStrToLower(path.extension().string());
  return ext == ".yaml" || ext == ".yml";
}

}  // namespace

absl::StatusOr<MapYaml> ParseMapYaml(std::string_view yaml_text, const MapLoadOptions& defaults) {
  if (yaml_text.size() > kMaxYamlBytes) {
    return absl::InvalidArgumentError(
        absl::StrFormat("map YAML is %d bytes; a map_server YAML is a few lines (limit %d)",
                        yaml_text.size(), kMaxYamlBytes));
  }
  // yaml-cpp reports syntax errors, bad conversions and excessive nesting by
  // exceptions; none may escape this library.
  try {
    const YAML::Node root = YAML::Load(std::string(yaml_text));
    return ParseMapYamlRoot(root, defaults);
  } catch (const YAML::Exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("bad map YAML: ", e.what()));
  } catch (const std::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("bad map YAML: ", e.what()));
  }
}

absl::StatusOr<OccupancyMap> LoadMapFile(const std::string& path, const MapLoadOptions& options) {
  const fs::path file(path);
  ASSIGN_OR_RETURN(const std::string bytes, ReadFile(file, options.max_file_bytes));
  if (!HasYamlExtension(file)) {
    absl::StatusOr<OccupancyMap> map = DecodeMapImage(bytes, options);
    if (!map.ok()) return WithPrefix(map.status(), path);
    return map;
  }
  absl::StatusOr<MapYaml> yaml = ParseMapYaml(bytes, options);
  if (!yaml.ok()) return WithPrefix(yaml.status(), path);
  fs::path image = fs::path(yaml->image);
  if (image.is_relative()) image = file.parent_path() / image;
  absl::StatusOr<std::string> image_bytes = ReadFile(image, yaml->options.max_file_bytes);
  if (!image_bytes.ok()) {
    return WithPrefix(image_bytes.status(), absl::StrCat(path, ": map image"));
  }
  absl::StatusOr<OccupancyMap> map = DecodeMapImage(*image_bytes, yaml->options);
  if (!map.ok()) return WithPrefix(map.status(), image.string());
  return map;
}

absl::Status SaveMapYamlPgm(const OccupancyMap& map, const std::string& yaml_path) {
  if (map.width() <= 0 || map.height() <= 0) {
    return absl::InvalidArgumentError("cannot save an empty map");
  }
  const fs::path yaml_file(yaml_path);
  if (!HasYamlExtension(yaml_file)) {
    return absl::InvalidArgumentError(
        absl::StrCat("map YAML path must end in .yaml or .yml, got ", yaml_path));
  }
  fs::path pgm_file = yaml_file;
  pgm_file.replace_extension(".pgm");

  std::string pgm =
      absl::StrFormat("P5\n# covplan occupancy map\n%d %d\n255\n", map.width(), map.height());
  const size_t header = pgm.size();
  pgm.resize(header + static_cast<size_t>(map.width()) * map.height());
  size_t i = header;
  for (int r = map.height() - 1; r >= 0; --r) {  // image top = largest y
    for (int c = 0; c < map.width(); ++c) {
      switch (map.at(r, c)) {
        case CellState::kFree:
          pgm[i++] = static_cast<char>(254);
          break;
        case CellState::kOccupied:
          pgm[i++] = static_cast<char>(0);
          break;
        case CellState::kUnknown:
          pgm[i++] = static_cast<char>(205);
          break;
      }
    }
  }
  RETURN_IF_ERROR(WriteFile(pgm_file, pgm));

  const std::string yaml =
      absl::StrCat("image: ", YamlQuote(pgm_file.filename().string()), "\n",
                   "resolution: ", ExactDouble(map.resolution()), "\n", "origin: [",
                   ExactDouble(map.origin().x), ", ", ExactDouble(map.origin().y), ", 0.0]\n",
                   "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n");
  return WriteFile(yaml_file, yaml);
}

}  // namespace covplan
