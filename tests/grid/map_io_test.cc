// Decoding map images (PGM P2/P5, PNG of every colour type and bit depth)
// into occupancy maps with ROS map_server semantics. Fixtures are built in
// the test; nothing is read from disk.
#include <png.h>
#include <zlib.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/grid/map_io.h"
#include "tests/grid/map_test_util.h"
#include "tests/testing/png_writer.h"

namespace covplan {
namespace {

using ::covplan::testing::EncodePng;
using ::covplan::testing::PngSpec;
using ::covplan::testing::StatusIs;
using ::covplan::testing::TopDown;
using ::testing::ElementsAre;
using Code = absl::StatusCode;

MapLoadOptions Opt() {
  MapLoadOptions o;
  o.resolution = 0.05;
  return o;
}

// Binary PGM, 8 bit for maxval < 256 else 16 bit big-endian; values top row first.
std::string P5(int w, int h, int maxval, const std::vector<int>& v) {
  std::string s = absl::StrCat("P5\n", w, " ", h, "\n", maxval, "\n");
  for (int x : v) {
    if (maxval > 255) s.push_back(static_cast<char>(x >> 8));
    s.push_back(static_cast<char>(x & 0xff));
  }
  return s;
}

TEST(DetectImageFormat, Magic) {
  EXPECT_EQ(DetectImageFormat("P5\n1 1\n255\n"), ImageFormat::kPgm);
  EXPECT_EQ(DetectImageFormat("P2 1 1 255 0"), ImageFormat::kPgm);
  EXPECT_EQ(DetectImageFormat(std::string("\x89PNG\r\n\x1a\n", 8)), ImageFormat::kPng);
  EXPECT_EQ(DetectImageFormat("P6\n"), ImageFormat::kUnknown);
  EXPECT_EQ(DetectImageFormat("\x89PNG"), ImageFormat::kUnknown);
  EXPECT_EQ(DetectImageFormat(""), ImageFormat::kUnknown);
}

// Thresholds 0.65 / 0.196: v <= 89 occupied, 90..205 unknown, >= 206 free.
TEST(DecodePgm, ThresholdsAtTheBoundaries) {
  auto map = DecodeMapImage(P5(7, 1, 255, {0, 89, 90, 205, 206, 254, 255}), Opt());
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("##??..."));
  EXPECT_EQ(map->width(), 7);
  EXPECT_EQ(map->height(), 1);
  EXPECT_DOUBLE_EQ(map->resolution(), 0.05);
}

// negate: p = v / 255, so v >= 166 occupied, 50..165 unknown, <= 49 free.
TEST(DecodePgm, Negate) {
  MapLoadOptions o = Opt();
  o.negate = true;
  auto map = DecodeMapImage(P5(7, 1, 255, {0, 49, 50, 165, 166, 205, 255}), o);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("..??###"));
}

TEST(DecodePgm, CustomThresholds) {
  MapLoadOptions o = Opt();
  o.free_thresh = 0.5;
  o.occupied_thresh = 0.9;
  // p: 255 -> 0, 128 -> 0.498, 127 -> 0.502, 25 -> 0.902, 26 -> 0.898
  auto map = DecodeMapImage(P5(5, 1, 255, {255, 128, 127, 26, 25}), o);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("..??#"));
}

TEST(DecodePgm, ImageTopRowIsLargestY) {
  auto map = DecodeMapImage(P5(3, 2, 255,
                               {0, 254, 254,  //
                                254, 254, 205}),
                            Opt());
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_EQ(map->at(1, 0), CellState::kOccupied);  // top-left pixel
  EXPECT_EQ(map->at(0, 2), CellState::kUnknown);   // bottom-right pixel
  EXPECT_EQ(map->at(0, 0), CellState::kFree);
  EXPECT_EQ(map->CountFree(), 4);
}

TEST(DecodePgm, AsciiWithCommentsEverywhere) {
  const std::string pgm =
      "P2 # magic\n# a full-line comment\n3# width\n 2 #height\n255\n"
      "0 254\t205\n# comment in the raster\n254 0\n 254\n";
  auto map = DecodeMapImage(pgm, Opt());
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("#.?", ".#."));
}

TEST(DecodePgm, BinaryCommentBeforeRasterAndTrailingBytes) {
  std::string pgm = "P5\n#c1\n2 #c2\n1\n255#c3\n";
  pgm += std::string("\x00\xfe", 2);
  pgm += "ignored second image";
  auto map = DecodeMapImage(pgm, Opt());
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("#."));
}

TEST(DecodePgm, SixteenBitBigEndianScaledTo8Bit) {
  // k * 257 scales to exactly k.
  auto map = DecodeMapImage(P5(5, 1, 65535, {0, 89 * 257, 205 * 257, 206 * 257, 65535}), Opt());
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("##?.."));
}

TEST(DecodePgm, OddMaxvals) {
  auto bilevel = DecodeMapImage(P5(2, 1, 1, {0, 1}), Opt());
  ASSERT_TRUE(bilevel.ok()) << bilevel.status();
  EXPECT_THAT(TopDown(*bilevel), ElementsAre("#."));
  // maxval 1000 (two bytes per sample): 800 -> 204 unknown, 810 -> 207 free.
  auto wide = DecodeMapImage(P5(3, 1, 1000, {800, 810, 349}), Opt());
  ASSERT_TRUE(wide.ok()) << wide.status();
  EXPECT_THAT(TopDown(*wide), ElementsAre("?.#"));
  auto ascii16 = DecodeMapImage("P2 2 1 65535 0 65535", Opt());
  ASSERT_TRUE(ascii16.ok()) << ascii16.status();
  EXPECT_THAT(TopDown(*ascii16), ElementsAre("#."));
}

TEST(DecodePgm, Errors) {
  const auto bad = [](const std::string& bytes, const char* substring) {
    EXPECT_THAT(DecodeMapImage(bytes, Opt()), StatusIs(Code::kInvalidArgument, substring))
        << "input: " << bytes;
  };
  bad("P5\n4 4\n255\n0123456789", "PGM is truncated: 4 x 4 pixels need 16 bytes");
  bad("P5\n4 4\n255", "PGM is truncated: no pixel data");
  bad("P5\n4 4\n", "missing maxval");
  bad("P5\n4", "missing height");
  bad("P5", "expected whitespace after the magic");
  bad("P5x 4 4 255\n", "expected whitespace after the magic");
  bad("P5\nfour 4\n255\n", "expected width as a decimal number, found 'f'");
  bad("P5\n0 4\n255\n", "zero size (0 x 4 pixels)");
  bad("P5\n4 0\n255\n", "zero size");
  bad("P5\n100000 100000\n255\n", "above the limit max_pixels");
  bad("P5\n99999999999999999999 1\n255\n", "width is larger than");
  bad("P5\n1 1\n0\n\x01", "maxval must be 1..65535");
  bad("P5\n1 1\n65536\n\x01\x01", "maxval is larger than 65535");
  bad("P5\n1 1\n255x", "expected whitespace after maxval");
  bad("P5\n2 1\n100\n\x10\x65", "pixel value 101 at row 0, column 1 exceeds maxval 100");
  bad("P2 3 1 255 0 1", "PGM is truncated");
  bad("P2 3 1 255 0 1     ", "missing pixel value");
  bad("P2 2 1 255 0 x", "expected pixel value as a decimal number");
  bad("P2 2 1 255 0 256", "exceeds maxval 255");
  bad("P6\n1 1\n255\n\0\0\0", "unsupported Netpbm format P6");
  bad("GIF89a", "unrecognised image format");
  bad("", "unrecognised image format");
}

// ---------------------------------------------------------------- PNG

PngSpec Grey(int bit_depth, std::vector<uint16_t> samples) {
  PngSpec s;
  s.width = static_cast<int>(samples.size());
  s.height = 1;
  s.color_type = PNG_COLOR_TYPE_GRAY;
  s.bit_depth = bit_depth;
  s.samples = std::move(samples);
  return s;
}

std::vector<std::string> DecodePngRows(const PngSpec& spec) {
  auto map = DecodeMapImage(EncodePng(spec), Opt());
  EXPECT_TRUE(map.ok()) << map.status();
  return map.ok() ? TopDown(*map) : std::vector<std::string>{};
}

TEST(DecodePng, GreyEveryBitDepth) {
  EXPECT_THAT(DecodePngRows(Grey(1, {0, 1, 1, 0})), ElementsAre("#..#"));
  // 2 bit: 0, 85, 170, 255.
  EXPECT_THAT(DecodePngRows(Grey(2, {0, 1, 2, 3})), ElementsAre("##?."));
  // 4 bit (x17): 5 -> 85, 6 -> 102, 12 -> 204, 13 -> 221.
  EXPECT_THAT(DecodePngRows(Grey(4, {5, 6, 12, 13, 15})), ElementsAre("#??.."));
  EXPECT_THAT(DecodePngRows(Grey(8, {0, 89, 90, 205, 206, 254})), ElementsAre("##??.."));
  EXPECT_THAT(DecodePngRows(Grey(16, {0, 89 * 257, 90 * 257, 205 * 257, 206 * 257, 65535})),
              ElementsAre("##??.."));
}

TEST(DecodePng, GreyAlphaIgnoresAlpha) {
  for (int depth : {8, 16}) {
    const uint16_t max = depth == 8 ? 255 : 65535;
    PngSpec s{3,     1,     PNG_COLOR_TYPE_GRAY_ALPHA,
              depth, false, {0, 0, max, 0, static_cast<uint16_t>(205 * (max / 255)), max},
              {},    {}};
    EXPECT_THAT(DecodePngRows(s), ElementsAre("#.?")) << "bit depth " << depth;
  }
}

// Colour is reduced to the mean of R, G, B as a real number, like map_server:
// (205, 205, 206) has mean 205.33, p = 0.1948 < 0.196 -> free.
TEST(DecodePng, RgbUsesChannelMean) {
  for (int depth : {8, 16}) {
    const uint16_t k = depth == 8 ? 1 : 257;
    std::vector<uint16_t> rgb = {205, 205, 206, 205, 205, 205, 255, 0,  0,
                                 0,   255, 255, 90,  89,  89,  89,  89, 89};
    for (auto& v : rgb) v = static_cast<uint16_t>(v * k);
    PngSpec s{6, 1, PNG_COLOR_TYPE_RGB, depth, false, rgb, {}, {}};
    EXPECT_THAT(DecodePngRows(s), ElementsAre(".?#??#")) << "bit depth " << depth;

    std::vector<uint16_t> rgba = {254, 254, 254, 0, 0, 0, 0, 0, 205, 205, 205, 128};
    for (auto& v : rgba) v = static_cast<uint16_t>(v * k);
    PngSpec a{3, 1, PNG_COLOR_TYPE_RGB_ALPHA, depth, false, rgba, {}, {}};
    EXPECT_THAT(DecodePngRows(a), ElementsAre(".#?")) << "bit depth " << depth;
  }
}

TEST(DecodePng, PaletteEveryBitDepthWithAndWithoutTransparency) {
  for (int depth : {1, 2, 4, 8}) {
    PngSpec s;
    s.color_type = PNG_COLOR_TYPE_PALETTE;
    s.bit_depth = depth;
    s.palette = {{0, 0, 0}, {254, 254, 254}, {205, 205, 205}, {255, 0, 0}};
    s.palette.resize(std::min(4, 1 << depth));
    s.samples = depth == 1 ? std::vector<uint16_t>{0, 1, 1} : std::vector<uint16_t>{0, 1, 2, 3};
    s.width = static_cast<int>(s.samples.size());
    s.height = 1;
    const char* expected = depth == 1 ? "#.." : "#.?#";
    EXPECT_THAT(DecodePngRows(s), ElementsAre(expected)) << "bit depth " << depth;
    s.palette_alpha = {0, 0};  // transparent black stays black: alpha is ignored
    EXPECT_THAT(DecodePngRows(s), ElementsAre(expected)) << "tRNS, bit depth " << depth;
  }
}

TEST(DecodePng, InterlacedAndRowFlip) {
  PngSpec s;
  s.width = 9;
  s.height = 9;
  s.color_type = PNG_COLOR_TYPE_GRAY;
  s.bit_depth = 8;
  s.interlaced = true;
  for (int r = 0; r < 9; ++r) {
    for (int c = 0; c < 9; ++c) s.samples.push_back(r == 0 || c == r ? 0 : 254);
  }
  auto map = DecodeMapImage(EncodePng(s), Opt());
  ASSERT_TRUE(map.ok()) << map.status();
  for (int c = 0; c < 9; ++c) EXPECT_EQ(map->at(8, c), CellState::kOccupied) << c;
  EXPECT_EQ(map->at(0, 8), CellState::kOccupied);  // image (8, 8)
  EXPECT_EQ(map->at(0, 0), CellState::kFree);
  EXPECT_EQ(map->CountFree(), 9 * 9 - 9 - 8);
}

// A valid PNG whose IHDR we rewrite (with a correct CRC) to other dimensions.
std::string WithDimensions(std::string png, uint32_t w, uint32_t h) {
  for (int i = 0; i < 4; ++i) {
    png[16 + i] = static_cast<char>(w >> (24 - 8 * i));
    png[20 + i] = static_cast<char>(h >> (24 - 8 * i));
  }
  const uint32_t crc = static_cast<uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(png.data() + 12), 17));  // "IHDR" + data
  for (int i = 0; i < 4; ++i) png[29 + i] = static_cast<char>(crc >> (24 - 8 * i));
  return png;
}

TEST(DecodePng, Errors) {
  PngSpec s;
  s.width = 64;
  s.height = 64;
  s.color_type = PNG_COLOR_TYPE_RGB;
  for (int i = 0; i < 64 * 64 * 3; ++i) s.samples.push_back((i * 7919) % 251);
  const std::string good = EncodePng(s);
  ASSERT_TRUE(DecodeMapImage(good, Opt()).ok());

  EXPECT_THAT(DecodeMapImage(good.substr(0, good.size() / 2), Opt()),
              StatusIs(Code::kInvalidArgument, "corrupt PNG"));
  EXPECT_THAT(DecodeMapImage(good.substr(0, good.size() - 12), Opt()),  // no IEND
              StatusIs(Code::kInvalidArgument, "corrupt PNG: file is truncated"));
  EXPECT_THAT(DecodeMapImage(good.substr(0, 8), Opt()),
              StatusIs(Code::kInvalidArgument, "corrupt PNG: file is truncated"));
  std::string bad_crc = good;
  bad_crc[30] ^= 0x55;
  EXPECT_THAT(DecodeMapImage(bad_crc, Opt()), StatusIs(Code::kInvalidArgument, "corrupt PNG"));
  std::string bad_data = good;
  for (size_t i = good.size() / 2; i < good.size() / 2 + 16; ++i) bad_data[i] ^= 0x5a;
  EXPECT_THAT(DecodeMapImage(bad_data, Opt()), StatusIs(Code::kInvalidArgument, "corrupt PNG"));

  // Dimensions are checked from the header before any pixel buffer exists.
  EXPECT_THAT(DecodeMapImage(WithDimensions(good, 200000, 100000), Opt()),
              StatusIs(Code::kInvalidArgument,
                       "PNG image is 200000 x 100000 pixels, above "
                       "the limit max_pixels = 100000000"));
  EXPECT_THAT(DecodeMapImage(WithDimensions(good, 9000, 9000), Opt()),
              StatusIs(Code::kInvalidArgument, "PNG is truncated or corrupt: 9000 x 9000"));
  EXPECT_THAT(DecodeMapImage(WithDimensions(good, 0, 64), Opt()),
              StatusIs(Code::kInvalidArgument, "corrupt PNG"));
}

// ---------------------------------------------------------------- options

TEST(MapLoadOptions, Validate) {
  EXPECT_TRUE(Opt().Validate().ok());
  const char* kRes = "resolution must be a positive number of metres per pixel, got ";
  for (double r : {0.0, -0.05, std::nan(""), std::numeric_limits<double>::infinity()}) {
    MapLoadOptions o = Opt();
    o.resolution = r;
    EXPECT_THAT(o.Validate(), StatusIs(Code::kInvalidArgument, kRes)) << r;
    EXPECT_THAT(DecodeMapImage(P5(1, 1, 255, {0}), o), StatusIs(Code::kInvalidArgument, kRes));
  }
  MapLoadOptions zero;
  EXPECT_THAT(zero.Validate(), StatusIs(Code::kInvalidArgument, "got 0"));

  const char* kThresh = "0 <= free_thresh < occupied_thresh <= 1";
  for (auto [f, occ] : std::vector<std::pair<double, double>>{
           {0.5, 0.5}, {0.7, 0.6}, {-0.1, 0.65}, {0.196, 1.01}, {std::nan(""), 0.65}}) {
    MapLoadOptions o = Opt();
    o.free_thresh = f;
    o.occupied_thresh = occ;
    EXPECT_THAT(o.Validate(), StatusIs(Code::kInvalidArgument, kThresh)) << f << " " << occ;
  }
  MapLoadOptions edge = Opt();
  edge.free_thresh = 0.0;
  edge.occupied_thresh = 1.0;
  EXPECT_TRUE(edge.Validate().ok());

  MapLoadOptions o = Opt();
  o.max_pixels = 0;
  EXPECT_THAT(o.Validate(), StatusIs(Code::kInvalidArgument, "max_pixels must be positive"));
  o = Opt();
  o.max_file_bytes = -1;
  EXPECT_THAT(o.Validate(), StatusIs(Code::kInvalidArgument, "max_file_bytes must be positive"));
  o = Opt();
  o.origin.x = std::nan("");
  EXPECT_THAT(o.Validate(), StatusIs(Code::kInvalidArgument, "origin must be finite"));
}

TEST(MapLoadOptions, LimitsAndOriginApply) {
  MapLoadOptions o = Opt();
  o.max_pixels = 99;
  const std::string pgm = P5(10, 10, 255, std::vector<int>(100, 254));
  EXPECT_THAT(DecodeMapImage(pgm, o),
              StatusIs(Code::kInvalidArgument, "10 x 10 pixels, above the limit max_pixels = 99"));
  o.max_pixels = 100;
  o.max_file_bytes = 50;
  EXPECT_THAT(DecodeMapImage(pgm, o),
              StatusIs(Code::kInvalidArgument, "above the limit max_file_bytes = 50"));
  o.max_file_bytes = 1000;
  o.origin = {-3.5, 12.25};
  auto map = DecodeMapImage(pgm, o);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_EQ(map->CountFree(), 100);
  EXPECT_DOUBLE_EQ(map->origin().x, -3.5);
  EXPECT_DOUBLE_EQ(map->origin().y, 12.25);
}

}  // namespace
}  // namespace covplan
