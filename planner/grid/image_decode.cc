// Image decoding for map input: PGM (P2/P5) and PNG (libpng).
//
// Pixels are classified straight into CellState through a lookup table over
// the *sum* of the colour channels (0..765), so the mean of R, G, B is used
// exactly as map_server does (no rounding to an 8-bit grey first). Grey
// images index the table with 3 * v.
#include "planner/grid/map_io.h"

#include <png.h>

#include <array>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

// OccupancyMap indexes with int; also bounds header numbers before multiplying.
constexpr int64_t kMaxSide = 1 << 30;
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
    return absl::InvalidArgumentError(
        absl::StrFormat("%s image is %d x %d pixels, above the limit max_pixels = %d", format,
                        width, height, o.max_pixels));
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
        return absl::InvalidArgumentError(absl::StrCat("bad PGM: ", what, " is larger than ", max));
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
  if (tok.remaining() == 0 || (!IsPgmSpace(bytes[2]) && bytes[2] != '#')) {
    return absl::InvalidArgumentError("bad PGM header: expected whitespace after the magic number");
  }
  ASSIGN_OR_RETURN(const int64_t width, tok.Number("width", kMaxSide));
  ASSIGN_OR_RETURN(const int64_t height, tok.Number("height", kMaxSide));
  ASSIGN_OR_RETURN(const int64_t maxval, tok.Number("maxval", 65535));
  if (maxval == 0)
    return absl::InvalidArgumentError("bad PGM header: maxval must be 1..65535, got 0");
  RETURN_IF_ERROR(CheckDimensions("PGM", width, height, o));

  const int64_t pixels = width * height;
  const int bytes_per_sample = maxval > 255 ? 2 : 1;
  if (binary) {
    RETURN_IF_ERROR(tok.SingleSeparator());
    if (static_cast<int64_t>(tok.remaining()) < pixels * bytes_per_sample) {
      return absl::InvalidArgumentError(
          absl::StrFormat("PGM is truncated: %d x %d pixels need %d bytes of pixel data, found %d",
                          width, height, pixels * bytes_per_sample, tok.remaining()));
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
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, PngErrorFn, PngWarningFn);
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
    return absl::InternalError(
        absl::StrFormat("unexpected PNG layout after conversion: %d channels, %d bytes per row",
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
      const int sum =
          layout.channels == 1 ? 3 * row[c] : row[3 * c] + row[3 * c + 1] + row[3 * c + 2];
      map.set(height - 1 - r, c, lut[sum]);
    }
  }
  return map;
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

absl::StatusOr<OccupancyMap> DecodeMapImage(std::string_view bytes, const MapLoadOptions& options) {
  RETURN_IF_ERROR(options.Validate());
  if (static_cast<int64_t>(bytes.size()) > options.max_file_bytes) {
    return absl::InvalidArgumentError(
        absl::StrFormat("image is %d bytes, above the limit max_file_bytes = %d", bytes.size(),
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
    return absl::InvalidArgumentError(
        absl::StrCat("unsupported Netpbm format P", std::string(1, bytes[1]),
                     ": only greyscale PGM (P2, P5) and PNG maps are supported"));
  }
  return absl::InvalidArgumentError(
      "unrecognised image format: expected a PGM (magic P2/P5) or PNG file");
}

}  // namespace covplan
