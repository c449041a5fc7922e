// Map input/output: PGM (P2/P5), PNG (libpng) and ROS map_server YAML.
//
// Pixels are classified straight into CellState through a lookup table over
// the *sum* of the colour channels (0..765), so the mean of R, G, B is used
// exactly as map_server does (no rounding to an 8-bit grey first). Grey
// images index the table with 3 * v.
#include "planner/grid/map_io.h"

#include <png.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

namespace fs = std::filesystem;

// OccupancyMap indexes with int; also bounds header numbers before multiplying.
constexpr int64_t kMaxSide = 1 << 30;
// A map_server YAML is a handful of lines; anything bigger is not one.
constexpr size_t kMaxYamlBytes = 1 << 20;
// Deflate cannot expand data by more than 1032:1; used to reject PNG headers
// that promise far more pixels than the file can hold before allocating.
constexpr int64_t kMaxDeflateRatio = 1032;

// Cell state for every channel sum s in 0..765 (mean grey = s / 3).
using ClassifyLut = std::array<CellState, 766>;

ClassifyLut MakeLut(const MapLoadOptions& o) {
  ClassifyLut lut;
  for (int s = 0; s < static_cast<int>(lut.size()); ++s) {
    const double v = s / 3.0;
    const double p = o.negate ? v / 255.0 : (255.0 - v) / 255.0;
    lut[s] = p > o.occupied_thresh ? CellState::kOccupied
             : p < o.free_thresh   ? CellState::kFree
                                   : CellState::kUnknown;
  }
  return lut;
}

absl::Status CheckDimensions(const char* format, int64_t width, int64_t height,
                             const MapLoadOptions& o) {
  if (width <= 0 || height <= 0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s image has zero size (%d x %d pixels)", format, width, height));
  }
  if (width > kMaxSide || height > kMaxSide || width * height > o.max_pixels) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s image is %d x %d pixels, above the limit max_pixels = %d", format, width,
        height, o.max_pixels));
  }
  return absl::OkStatus();
}

// ---------------------------------------------------------------- PGM

bool IsPgmSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// Reads the whitespace/comment separated decimal numbers of a PGM header (and
// of a P2 raster). '#' starts a comment that runs to the end of the line.
class PgmTokenizer {
 public:
  PgmTokenizer(std::string_view bytes, size_t pos) : s_(bytes), pos_(pos) {}

  size_t pos() const { return pos_; }
  size_t remaining() const { return s_.size() - pos_; }

  void SkipSpaceAndComments() {
    while (pos_ < s_.size()) {
      if (s_[pos_] == '#') {
        while (pos_ < s_.size() && s_[pos_] != '\n' && s_[pos_] != '\r') ++pos_;
      } else if (IsPgmSpace(s_[pos_])) {
        ++pos_;
      } else {
        return;
      }
    }
  }

  // `what` names the field for error messages; values above `max` are rejected.
  absl::StatusOr<int64_t> Number(const char* what, int64_t max) {
    SkipSpaceAndComments();
    if (pos_ >= s_.size()) {
      return absl::InvalidArgumentError(absl::StrCat("PGM is truncated: missing ", what));
    }
    if (!absl::ascii_isdigit(static_cast<unsigned char>(s_[pos_]))) {
      return absl::InvalidArgumentError(
          absl::StrCat("bad PGM header: expected ", what, " as a decimal number, found '",
                       absl::CHexEscape(absl::string_view(s_.data() + pos_, 1)), "'"));
    }
    int64_t v = 0;
    while (pos_ < s_.size() && absl::ascii_isdigit(static_cast<unsigned char>(s_[pos_]))) {
      v = v * 10 + (s_[pos_++] - '0');
      if (v > max) {
        return absl::InvalidArgumentError(
            absl::StrCat("bad PGM: ", what, " is larger than ", max));
      }
    }
    return v;
  }

  // Exactly one whitespace character (or a comment ending in a newline)
  // separates maxval from a binary raster.
  absl::Status SingleSeparator() {
    if (pos_ >= s_.size()) return absl::InvalidArgumentError("PGM is truncated: no pixel data");
    if (s_[pos_] == '#') {
      while (pos_ < s_.size() && s_[pos_] != '\n' && s_[pos_] != '\r') ++pos_;
      if (pos_ >= s_.size()) return absl::InvalidArgumentError("PGM is truncated: no pixel data");
    } else if (!IsPgmSpace(s_[pos_])) {
      return absl::InvalidArgumentError("bad PGM header: expected whitespace after maxval");
    }
    ++pos_;
    return absl::OkStatus();
  }

 private:
  std::string_view s_;
  size_t pos_;
};

absl::StatusOr<OccupancyMap> DecodePgm(std::string_view bytes, const MapLoadOptions& o) {
  const bool binary = bytes[1] == '5';
  PgmTokenizer tok(bytes, 2);
  if (tok.remaining() == 0 ||
      (!IsPgmSpace(bytes[2]) && bytes[2] != '#')) {
    return absl::InvalidArgumentError("bad PGM header: expected whitespace after the magic number");
  }
  ASSIGN_OR_RETURN(const int64_t width, tok.Number("width", kMaxSide));
  ASSIGN_OR_RETURN(const int64_t height, tok.Number("height", kMaxSide));
  ASSIGN_OR_RETURN(const int64_t maxval, tok.Number("maxval", 65535));
  if (maxval == 0) return absl::InvalidArgumentError("bad PGM header: maxval must be 1..65535, got 0");
  RETURN_IF_ERROR(CheckDimensions("PGM", width, height, o));

  const int64_t pixels = width * height;
  const int bytes_per_sample = maxval > 255 ? 2 : 1;
  if (binary) {
    RETURN_IF_ERROR(tok.SingleSeparator());
    if (static_cast<int64_t>(tok.remaining()) < pixels * bytes_per_sample) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "PGM is truncated: %d x %d pixels need %d bytes of pixel data, found %d", width,
          height, pixels * bytes_per_sample, tok.remaining()));
    }
  } else if (static_cast<int64_t>(tok.remaining()) < 2 * pixels - 1) {
    // Each ASCII sample takes a digit and a separator: cheap early rejection.
    return absl::InvalidArgumentError(absl::StrFormat(
        "PGM is truncated: %d bytes cannot hold %d ASCII pixel values", tok.remaining(), pixels));
  }

  const ClassifyLut lut = MakeLut(o);
  OccupancyMap map(static_cast<int>(width), static_cast<int>(height), o.resolution, o.origin);
  const unsigned char* raster = reinterpret_cast<const unsigned char*>(bytes.data()) + tok.pos();
  for (int64_t r = 0; r < height; ++r) {
    const int map_row = static_cast<int>(height - 1 - r);  // image top = largest y
    for (int64_t c = 0; c < width; ++c) {
      int64_t raw;
      if (binary) {
        const int64_t i = (r * width + c) * bytes_per_sample;
        raw = bytes_per_sample == 2 ? (raster[i] << 8) | raster[i + 1] : raster[i];
      } else {
        ASSIGN_OR_RETURN(raw, tok.Number("pixel value", 65535));
      }
      if (raw > maxval) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bad PGM: pixel value %d at row %d, column %d exceeds maxval %d", raw, r, c, maxval));
      }
      const int64_t v = (raw * 255 + maxval / 2) / maxval;  // scaled to 0..255
      map.set(map_row, static_cast<int>(c), lut[3 * v]);
    }
  }
  return map;
}

// ---------------------------------------------------------------- PNG
//
// The classic libpng API reports errors by longjmp. Every function below that
// calls setjmp, and every callback libpng may call, holds only trivially
// destructible objects, so the jump never skips a C++ destructor. C++ objects
// (the pixel buffer, the map) live in DecodePng, which no jump crosses.

struct PngSource {
  const unsigned char* data;
  size_t size;
  size_t pos;
  char error[200];
};

[[noreturn]] void PngErrorFn(png_structp png, png_const_charp message) {
  auto* src = static_cast<PngSource*>(png_get_error_ptr(png));
  std::snprintf(src->error, sizeof(src->error), "%s", message);
  png_longjmp(png, 1);
}

void PngWarningFn(png_structp, png_const_charp) {}  // warnings are not failures

void PngReadFn(png_structp png, png_bytep out, size_t n) {
  auto* src = static_cast<PngSource*>(png_get_io_ptr(png));
  if (src->size - src->pos < n) png_error(png, "file is truncated");
  std::memcpy(out, src->data + src->pos, n);
  src->pos += n;
}

struct PngLayout {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  size_t file_rowbytes = 0;  // before transformations
  int channels = 0;          // after transformations: 1 (grey) or 3 (RGB)
  size_t rowbytes = 0;       // after transformations
};

// Reads the header (all chunks up to the first IDAT).
bool PngReadHeader(png_structp png, png_infop info, PngLayout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  layout->width = png_get_image_width(png, info);
  layout->height = png_get_image_height(png, info);
  layout->file_rowbytes = png_get_rowbytes(png, info);
  return true;
}

// Requests 8-bit grey or RGB without alpha; palette and low bit depths are
// expanded, 16-bit samples are scaled (rounded) to 8 bits. No gamma handling:
// sample values are taken as they are, like map_server does.
bool PngSetTransforms(png_structp png, png_infop info, PngLayout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  const int color_type = png_get_color_type(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(png);
  }
  if (bit_depth == 16) png_set_scale_16(png);
  png_set_strip_alpha(png);  // also drops the alpha a tRNS chunk would add
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout->channels = png_get_channels(png, info);
  layout->rowbytes = png_get_rowbytes(png, info);
  return true;
}

bool PngReadPixels(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);  // checks the trailing chunks: catches truncation
  return true;
}

absl::StatusOr<OccupancyMap> DecodePng(std::string_view bytes, const MapLoadOptions& o) {
  PngSource src{reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), 0, {}};
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, PngErrorFn, PngWarningFn);
  if (png == nullptr) return absl::ResourceExhaustedError("cannot allocate PNG decoder");
  png_infop info = png_create_info_struct(png);
  struct Destroy {
    png_structp* png;
    png_infop* info;
    ~Destroy() { png_destroy_read_struct(png, info, nullptr); }
  } destroy{&png, &info};
  if (info == nullptr) return absl::ResourceExhaustedError("cannot allocate PNG decoder");
  png_set_read_fn(png, &src, PngReadFn);
  auto png_failure = [&src] {
    return absl::InvalidArgumentError(absl::StrCat("corrupt PNG: ", src.error));
  };

  PngLayout layout;
  if (!PngReadHeader(png, info, &layout)) return png_failure();
  RETURN_IF_ERROR(CheckDimensions("PNG", layout.width, layout.height, o));
  const int64_t raw_bytes = static_cast<int64_t>(layout.height) * layout.file_rowbytes;
  const int64_t compressed_bytes = static_cast<int64_t>(src.size - src.pos);
  if (raw_bytes > kMaxDeflateRatio * compressed_bytes + 4096) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "PNG is truncated or corrupt: %u x %u pixels need %d bytes of image data, which "
        "%d remaining bytes cannot hold",
        layout.width, layout.height, raw_bytes, compressed_bytes));
  }
  if (!PngSetTransforms(png, info, &layout)) return png_failure();
  if ((layout.channels != 1 && layout.channels != 3) ||
      layout.rowbytes != static_cast<size_t>(layout.width) * layout.channels) {
    return absl::InternalError(absl::StrFormat(
        "unexpected PNG layout after conversion: %d channels, %d bytes per row",
        layout.channels, layout.rowbytes));
  }

  std::vector<unsigned char> pixels(layout.rowbytes * layout.height);
  std::vector<png_bytep> rows(layout.height);
  for (png_uint_32 r = 0; r < layout.height; ++r) rows[r] = &pixels[r * layout.rowbytes];
  if (!PngReadPixels(png, rows.data())) return png_failure();

  const ClassifyLut lut = MakeLut(o);
  const int width = static_cast<int>(layout.width);
  const int height = static_cast<int>(layout.height);
  OccupancyMap map(width, height, o.resolution, o.origin);
  for (int r = 0; r < height; ++r) {
    const unsigned char* row = rows[r];
    for (int c = 0; c < width; ++c) {
      const int sum = layout.channels == 1
                          ? 3 * row[c]
                          : row[3 * c] + row[3 * c + 1] + row[3 * c + 2];
      map.set(height - 1 - r, c, lut[sum]);
    }
  }
  return map;
}

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
  return absl::InvalidArgumentError(absl::StrCat(
      "'negate' must be 0, 1, true or false",
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
      return absl::InvalidArgumentError(absl::StrCat(
          "map mode '", mode.IsScalar() ? mode.Scalar() : "?",
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
    return absl::InvalidArgumentError(absl::StrCat(path.string(), " is a directory, not a map file"));
  }
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return absl::InvalidArgumentError(absl::StrCat("cannot read ", path.string(), ": ", ec.message()));
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

absl::Status MapLoadOptions::Validate() const {
  if (!std::isfinite(resolution) || resolution <= 0.0) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "resolution must be a positive number of metres per pixel, got %g", resolution));
  }
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("origin must be finite, got (%g, %g)", origin.x, origin.y));
  }
  if (!(free_thresh >= 0.0 && free_thresh < occupied_thresh && occupied_thresh <= 1.0)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1, got free_thresh = "
        "%g, occupied_thresh = %g",
        free_thresh, occupied_thresh));
  }
  if (max_pixels <= 0) return absl::InvalidArgumentError("max_pixels must be positive");
  if (max_file_bytes <= 0) return absl::InvalidArgumentError("max_file_bytes must be positive");
  return absl::OkStatus();
}

ImageFormat DetectImageFormat(std::string_view bytes) {
  static constexpr char kPngSignature[] = "\x89PNG\r\n\x1a\n";
  if (bytes.size() >= 8 && bytes.substr(0, 8) == std::string_view(kPngSignature, 8)) {
    return ImageFormat::kPng;
  }
  if (bytes.size() >= 2 && bytes[0] == 'P' && (bytes[1] == '2' || bytes[1] == '5')) {
    return ImageFormat::kPgm;
  }
  return ImageFormat::kUnknown;
}

absl::StatusOr<OccupancyMap> DecodeMapImage(std::string_view bytes,
                                            const MapLoadOptions& options) {
  RETURN_IF_ERROR(options.Validate());
  if (static_cast<int64_t>(bytes.size()) > options.max_file_bytes) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "image is %d bytes, above the limit max_file_bytes = %d", bytes.size(),
        options.max_file_bytes));
  }
  switch (DetectImageFormat(bytes)) {
    case ImageFormat::kPgm:
      return DecodePgm(bytes, options);
    case ImageFormat::kPng:
      return DecodePng(bytes, options);
    case ImageFormat::kUnknown:
      break;
  }
  if (bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '7') {
    return absl::InvalidArgumentError(absl::StrCat(
        "unsupported Netpbm format P", std::string(1, bytes[1]),
        ": only greyscale PGM (P2, P5) and PNG maps are supported"));
  }
  return absl::InvalidArgumentError(
      "unrecognised image format: expected a PGM (magic P2/P5) or PNG file");
}

absl::StatusOr<MapYaml> ParseMapYaml(std::string_view yaml_text, const MapLoadOptions& defaults) {
  if (yaml_text.size() > kMaxYamlBytes) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "map YAML is %d bytes; a map_server YAML is a few lines (limit %d)", yaml_text.size(),
        kMaxYamlBytes));
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

  std::string pgm = absl::StrFormat("P5\n# covplan occupancy map\n%d %d\n255\n", map.width(),
                                    map.height());
  const size_t header = pgm.size();
  pgm.resize(header + static_cast<size_t>(map.width()) * map.height());
  size_t i = header;
  for (int r = map.height() - 1; r >= 0; --r) {  // image top = largest y
    for (int c = 0; c < map.width(); ++c) {
      switch (map.at(r, c)) {
        case CellState::kFree: pgm[i++] = static_cast<char>(254); break;
        case CellState::kOccupied: pgm[i++] = static_cast<char>(0); break;
        case CellState::kUnknown: pgm[i++] = static_cast<char>(205); break;
      }
    }
  }
  RETURN_IF_ERROR(WriteFile(pgm_file, pgm));

  const std::string yaml = absl::StrCat(
      "image: ", YamlQuote(pgm_file.filename().string()), "\n",
      "resolution: ", ExactDouble(map.resolution()), "\n",
      "origin: [", ExactDouble(map.origin().x), ", ", ExactDouble(map.origin().y), ", 0.0]\n",
      "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n");
  return WriteFile(yaml_file, yaml);
}

}  // namespace covplan
