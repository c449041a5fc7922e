#include "tests/testing/png_writer.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstdlib>

namespace covplan::testing {
namespace {

void WriteFn(png_structp png, png_bytep data, size_t n) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<char*>(data), n);
}
void FlushFn(png_structp) {}

// Holds no C++ objects with destructors: libpng errors longjmp back here.
bool WritePng(png_structp png, png_infop info, const PngSpec& spec, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.color_type,
               spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (spec.color_type == PNG_COLOR_TYPE_PALETTE) {
    png_color colors[256];
    const int n = static_cast<int>(spec.palette.size());
    for (int i = 0; i < n && i < 256; ++i) {
      colors[i] = {spec.palette[i][0], spec.palette[i][1], spec.palette[i][2]};
    }
    png_set_PLTE(png, info, colors, n);
    if (!spec.palette_alpha.empty()) {
      png_set_tRNS(png, info, spec.palette_alpha.data(),
                   static_cast<int>(spec.palette_alpha.size()), nullptr);
    }
  }
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

}  // namespace

int PngChannels(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return 2;
    case PNG_COLOR_TYPE_RGB:
      return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
    default:
      return 1;  // grey, palette
  }
}

std::string EncodePng(const PngSpec& spec) {
  const int channels = PngChannels(spec.color_type);
  const size_t samples_per_row = static_cast<size_t>(spec.width) * channels;
  if (spec.samples.size() != samples_per_row * spec.height) {
    std::fprintf(stderr, "EncodePng: %zu samples for a %dx%d image\n", spec.samples.size(),
                 spec.width, spec.height);
    std::abort();
  }
  const size_t row_bytes = (samples_per_row * spec.bit_depth + 7) / 8;
  std::vector<std::vector<png_byte>> rows(spec.height, std::vector<png_byte>(row_bytes, 0));
  for (int r = 0; r < spec.height; ++r) {
    for (size_t i = 0; i < samples_per_row; ++i) {
      const unsigned v = spec.samples[r * samples_per_row + i];
      if (spec.bit_depth == 16) {
        rows[r][2 * i] = static_cast<png_byte>(v >> 8);
        rows[r][2 * i + 1] = static_cast<png_byte>(v & 0xff);
      } else {  // pack MSB first
        const size_t bit = i * spec.bit_depth;
        const int shift = 8 - spec.bit_depth - static_cast<int>(bit % 8);
        rows[r][bit / 8] |= static_cast<png_byte>(v << shift);
      }
    }
  }
  std::vector<png_bytep> row_ptrs;
  for (auto& row : rows) row_ptrs.push_back(row.data());

  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_set_write_fn(png, &out, WriteFn, FlushFn);
  const bool ok = WritePng(png, info, spec, row_ptrs.data());
  png_destroy_write_struct(&png, &info);
  if (!ok) {
    std::fprintf(stderr, "EncodePng: libpng failed\n");
    std::abort();
  }
  return out;
}

}  // namespace covplan::testing
