// Reading occupancy maps: ROS map_server YAML (+ PGM/PNG image), bare PGM
// (P2/P5, 8/16 bit) and PNG (grey, grey+alpha, RGB, RGBA, palette; 8/16 bit).
//
// Semantics follow ROS map_server: for `negate: 0`, p = (255 - v) / 255
// (v = grey value scaled to 0..255, colour converted to grey by the mean of
// R, G, B); p > occupied_thresh -> occupied, p < free_thresh -> free, else
// unknown. A pixel with alpha < 255... is treated by its grey value only (alpha
// ignored, as map_server's "trinary" mode does). Image row 0 is the *top* of
// the picture, which is the largest y; OccupancyMap row 0 is the smallest y,
// so rows are flipped on load.
//
//   MapLoadOptions opt;
//   opt.resolution = 0.05;                        // required for bare images
//   absl::StatusOr<OccupancyMap> map = LoadMapFile("site.yaml", opt);
//
// Every failure is InvalidArgument with a message naming the file and the
// problem (truncated data, bad header, missing key, bad threshold, ...), or
// NotFound for a missing file. Never crashes on malformed input.
// Thread-safety: stateless free functions, safe to call concurrently.
#ifndef COVPLAN_PLANNER_GRID_MAP_IO_H_
#define COVPLAN_PLANNER_GRID_MAP_IO_H_

#include <cstdint>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

enum class ImageFormat { kUnknown, kPgm, kPng };

struct MapLoadOptions {
  // For bare images (no YAML). Ignored when a YAML supplies them, unless
  // override_resolution is set.
  double resolution = 0.0;  // metres per pixel; required for bare images
  Point2 origin{0.0, 0.0};  // map-frame position of the bottom-left pixel corner
  bool negate = false;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  bool override_resolution = false;  // --resolution given explicitly with a YAML
  // Limits: an image beyond these is rejected with InvalidArgument.
  int64_t max_pixels = 100'000'000;
  int64_t max_file_bytes = 256ll << 20;

  absl::Status Validate() const;
};

// Sniffs the magic bytes.
ImageFormat DetectImageFormat(std::string_view bytes);

// Decodes image bytes (PGM or PNG, detected by magic) into an occupancy map
// using options.resolution/origin/negate/thresholds.
absl::StatusOr<OccupancyMap> DecodeMapImage(std::string_view bytes, const MapLoadOptions& options);

// Parses a map_server YAML text. `load_image(name)` returns the bytes of the
// image file the YAML names (relative to the YAML). The YAML's resolution,
// origin (x, y; yaw must be 0), negate, occupied_thresh and free_thresh
// override `options` (resolution only if !override_resolution).
// `mode` other than "trinary" / absent is rejected.
template <typename ImageLoader>
absl::StatusOr<OccupancyMap> DecodeMapYaml(std::string_view yaml_text, ImageLoader&& load_image,
                                           const MapLoadOptions& options);

// Parses the YAML into options plus the image file name (helper for the above
// and for the server, which receives YAML and image bytes separately).
struct MapYaml {
  std::string image;
  MapLoadOptions options;
};
absl::StatusOr<MapYaml> ParseMapYaml(std::string_view yaml_text, const MapLoadOptions& defaults);

// Loads a map from disk: `.yaml`/`.yml` -> YAML + image; otherwise an image.
absl::StatusOr<OccupancyMap> LoadMapFile(const std::string& path, const MapLoadOptions& options);

// Writes a map as YAML + 8-bit binary PGM (free 254, occupied 0, unknown 205).
absl::Status SaveMapYamlPgm(const OccupancyMap& map, const std::string& yaml_path);

// ---- implementation of the template ----
template <typename ImageLoader>
absl::StatusOr<OccupancyMap> DecodeMapYaml(std::string_view yaml_text, ImageLoader&& load_image,
                                           const MapLoadOptions& options) {
  absl::StatusOr<MapYaml> parsed = ParseMapYaml(yaml_text, options);
  if (!parsed.ok()) return parsed.status();
  absl::StatusOr<std::string> bytes = load_image(parsed->image);
  if (!bytes.ok()) return bytes.status();
  return DecodeMapImage(*bytes, parsed->options);
}

}  // namespace covplan

#endif  // COVPLAN_PLANNER_GRID_MAP_IO_H_
