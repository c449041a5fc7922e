// Test-only PNG encoder (libpng) for building map fixtures of every colour
// type and bit depth in memory.
//
//   PngSpec spec{.width = 2, .height = 1, .color_type = PNG_COLOR_TYPE_GRAY,
//                .bit_depth = 8, .samples = {0, 255}};
//   std::string bytes = EncodePng(spec);
//
// Thread-safety: stateless; safe to call concurrently.
#ifndef COVPLAN_TESTS_TESTING_PNG_WRITER_H_
#define COVPLAN_TESTS_TESTING_PNG_WRITER_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace covplan::testing {

struct PngSpec {
  int width = 0;
  int height = 0;
  int color_type = 0;  // PNG_COLOR_TYPE_*
  int bit_depth = 8;
  bool interlaced = false;
  // Row-major, top row first, `channels` samples per pixel in the file's own
  // range (0 .. 2^bit_depth - 1); palette images hold palette indices.
  std::vector<uint16_t> samples;
  std::vector<std::array<uint8_t, 3>> palette;  // PNG_COLOR_TYPE_PALETTE only
  std::vector<uint8_t> palette_alpha;           // optional tRNS for palettes
};

// Samples per pixel of a PNG colour type.
int PngChannels(int color_type);

// Encodes `spec`; aborts the test binary on a libpng error (a broken fixture).
std::string EncodePng(const PngSpec& spec);

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_PNG_WRITER_H_
