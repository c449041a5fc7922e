// map_server YAML parsing, loading maps from disk, saving and the shipped
// sample maps. Fixtures are written to a per-test temporary directory.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/grid/map_io.h"
#include "tests/grid/map_test_util.h"

namespace covplan {
namespace {

namespace fs = std::filesystem;
using ::covplan::testing::StatusIs;
using ::covplan::testing::TopDown;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using Code = absl::StatusCode;

// 3 x 2 PGM: top row "#.?", bottom row "..#".
const char kPgm[] = "P2 3 2 255\n0 254 205\n254 254 0\n";

// ---------------------------------------------------------------- ParseMapYaml

TEST(ParseMapYaml, RequiredKeysAndDefaults) {
  MapLoadOptions defaults;
  defaults.max_pixels = 1234;
  auto y = ParseMapYaml("image: map.pgm\nresolution: 0.1\n", defaults);
  ASSERT_TRUE(y.ok()) << y.status();
  EXPECT_EQ(y->image, "map.pgm");
  EXPECT_DOUBLE_EQ(y->options.resolution, 0.1);
  EXPECT_DOUBLE_EQ(y->options.origin.x, 0.0);
  EXPECT_DOUBLE_EQ(y->options.origin.y, 0.0);
  EXPECT_FALSE(y->options.negate);
  EXPECT_DOUBLE_EQ(y->options.occupied_thresh, 0.65);
  EXPECT_DOUBLE_EQ(y->options.free_thresh, 0.196);
  EXPECT_EQ(y->options.max_pixels, 1234);  // limits come from the caller
}

TEST(ParseMapYaml, EveryKeyOverrides) {
  auto y = ParseMapYaml(
      "image: \"dir/my map.png\"\nresolution: 0.025\norigin: [-10.5, 4.25, 0.0]\n"
      "negate: 1\noccupied_thresh: 0.9\nfree_thresh: 0.1\nmode: trinary\nextra: ignored\n",
      MapLoadOptions{});
  ASSERT_TRUE(y.ok()) << y.status();
  EXPECT_EQ(y->image, "dir/my map.png");
  EXPECT_DOUBLE_EQ(y->options.resolution, 0.025);
  EXPECT_DOUBLE_EQ(y->options.origin.x, -10.5);
  EXPECT_DOUBLE_EQ(y->options.origin.y, 4.25);
  EXPECT_TRUE(y->options.negate);
  EXPECT_DOUBLE_EQ(y->options.occupied_thresh, 0.9);
  EXPECT_DOUBLE_EQ(y->options.free_thresh, 0.1);
}

TEST(ParseMapYaml, NegateSpellingsAndTwoElementOrigin) {
  for (const char* v : {"1", "true", "True", "yes"}) {
    auto y = ParseMapYaml(absl::StrCat("{image: m.pgm, resolution: 1, negate: ", v, "}"), {});
    ASSERT_TRUE(y.ok()) << v << ": " << y.status();
    EXPECT_TRUE(y->options.negate) << v;
  }
  for (const char* v : {"0", "false", "no"}) {
    MapLoadOptions d;
    d.negate = true;
    auto y = ParseMapYaml(absl::StrCat("{image: m.pgm, resolution: 1, negate: ", v, "}"), d);
    ASSERT_TRUE(y.ok()) << v << ": " << y.status();
    EXPECT_FALSE(y->options.negate) << v;
  }
  auto y = ParseMapYaml("image: m.pgm\nresolution: 1\norigin: [1, 2]\n", {});
  ASSERT_TRUE(y.ok()) << y.status();
  EXPECT_DOUBLE_EQ(y->options.origin.y, 2.0);
}

TEST(ParseMapYaml, OverrideResolution) {
  MapLoadOptions d;
  d.resolution = 0.2;
  d.override_resolution = true;
  auto y = ParseMapYaml("image: m.pgm\nresolution: 0.05\n", d);
  ASSERT_TRUE(y.ok()) << y.status();
  EXPECT_DOUBLE_EQ(y->options.resolution, 0.2);
  auto no_res = ParseMapYaml("image: m.pgm\n", d);  // the override supplies it
  ASSERT_TRUE(no_res.ok()) << no_res.status();
  EXPECT_DOUBLE_EQ(no_res->options.resolution, 0.2);
}

TEST(ParseMapYaml, Errors) {
  const auto bad = [](const std::string& yaml, const char* substring) {
    EXPECT_THAT(ParseMapYaml(yaml, MapLoadOptions{}), StatusIs(Code::kInvalidArgument, substring))
        << "yaml: " << yaml;
  };
  bad("resolution: 0.05\n", "missing the required key 'image'");
  bad("image:\nresolution: 0.05\n", "missing the required key 'image'");
  bad("image: [a, b]\nresolution: 0.05\n", "'image' must be the name");
  bad("image: m.pgm\n", "missing the required key 'resolution'");
  bad("image: m.pgm\nresolution: fine\n", "'resolution' must be a number, got 'fine'");
  bad("image: m.pgm\nresolution: 0\n", "resolution must be a positive number");
  bad("image: m.pgm\nresolution: -1\n", "got -1");
  bad("image: m.pgm\nresolution: .nan\n", "got nan");
  bad("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0.5]\n",
      "rotated maps are not supported (origin yaw = 0.5)");
  bad("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0, 0]\n", "'origin' must be a list");
  bad("image: m.pgm\nresolution: 0.05\norigin: 3\n", "'origin' must be a list");
  bad("image: m.pgm\nresolution: 0.05\norigin: [a, 0]\n", "'origin x' must be a number");
  bad("image: m.pgm\nresolution: 0.05\nnegate: 2\n", "'negate' must be 0, 1, true or false");
  bad("image: m.pgm\nresolution: 0.05\nmode: scale\n", "map mode 'scale' is not supported");
  bad("image: m.pgm\nresolution: 0.05\nmode: raw\n", "map mode 'raw' is not supported");
  bad("image: m.pgm\nresolution: 0.05\nfree_thresh: 0.7\n",
      "0 <= free_thresh < occupied_thresh <= 1");
  bad("image: m.pgm\nresolution: 0.05\noccupied_thresh: 1.5\n", "occupied_thresh = 1.5");
  bad("image: m.pgm\nresolution: 0.05\nfree_thresh: [1]\n", "'free_thresh' must be a number");
  bad("image: [m.pgm\nresolution: 0.05\n", "bad map YAML: yaml-cpp: error at line");
  bad("{image: m.pgm, {\n", "bad map YAML");
  bad("just a string", "must be a mapping");
  bad("", "must be a mapping");
  bad(std::string(10000, '[') + std::string(10000, ']'), "bad map YAML");
}

TEST(DecodeMapYaml, LoadsTheNamedImage) {
  const std::map<std::string, std::string> files = {{"a.pgm", kPgm}};
  std::vector<std::string> asked;
  auto loader = [&](const std::string& name) -> absl::StatusOr<std::string> {
    asked.push_back(name);
    auto it = files.find(name);
    if (it == files.end()) return absl::NotFoundError(absl::StrCat("no file ", name));
    return it->second;
  };
  auto map = DecodeMapYaml("image: a.pgm\nresolution: 0.5\norigin: [1, 2, 0]\nnegate: 1\n", loader,
                           MapLoadOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre(".##", "##."));  // negated
  EXPECT_DOUBLE_EQ(map->resolution(), 0.5);
  EXPECT_DOUBLE_EQ(map->origin().x, 1.0);
  EXPECT_DOUBLE_EQ(map->origin().y, 2.0);
  EXPECT_THAT(DecodeMapYaml("image: b.pgm\nresolution: 1\n", loader, MapLoadOptions{}),
              StatusIs(Code::kNotFound, "no file b.pgm"));
  EXPECT_THAT(asked, ElementsAre("a.pgm", "b.pgm"));
}

// ---------------------------------------------------------------- files

class MapFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / absl::StrCat("covplan_map_io_", info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "maps");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& data) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << data;
    return p.string();
  }

  fs::path dir_;
};

TEST_F(MapFileTest, YamlImageIsRelativeToTheYaml) {
  Write("maps/site.pgm", kPgm);
  const std::string yaml =
      Write("maps/site.yaml", "image: site.pgm\nresolution: 0.05\norigin: [-1, -2, 0]\n");
  auto map = LoadMapFile(yaml, MapLoadOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("#.?", "..#"));
  EXPECT_DOUBLE_EQ(map->origin().x, -1.0);
  EXPECT_DOUBLE_EQ(map->origin().y, -2.0);
  EXPECT_DOUBLE_EQ(map->resolution(), 0.05);
}

TEST_F(MapFileTest, AbsoluteImagePathAndYmlExtension) {
  const std::string pgm = Write("elsewhere.pgm", kPgm);
  const std::string yaml =
      Write("maps/site.YML", absl::StrCat("image: ", pgm, "\nresolution: 0.1\n"));
  auto map = LoadMapFile(yaml, MapLoadOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_EQ(map->CountFree(), 3);
}

TEST_F(MapFileTest, BareImagesAreDetectedByMagic) {
  const std::string path = Write("map.png", kPgm);  // PGM bytes despite the name
  MapLoadOptions o;
  EXPECT_THAT(LoadMapFile(path, o),
              StatusIs(Code::kInvalidArgument,
                       path + ": resolution must be a positive number of metres per pixel, "
                              "got 0"));
  o.resolution = 0.05;
  auto map = LoadMapFile(path, o);
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_THAT(TopDown(*map), ElementsAre("#.?", "..#"));
}

TEST_F(MapFileTest, Errors) {
  const std::string missing = (dir_ / "nope.yaml").string();
  EXPECT_THAT(LoadMapFile(missing, MapLoadOptions{}), StatusIs(Code::kNotFound, missing));
  const std::string yaml = Write("maps/a.yaml", "image: gone.pgm\nresolution: 0.05\n");
  EXPECT_THAT(LoadMapFile(yaml, MapLoadOptions{}),
              StatusIs(Code::kNotFound, (dir_ / "maps" / "gone.pgm").string()));
  EXPECT_THAT(LoadMapFile(dir_.string(), MapLoadOptions{}),
              StatusIs(Code::kInvalidArgument, "is a directory"));

  const std::string bad_yaml = Write("maps/b.yaml", "image: a.pgm\nresolution: 0.05\nmode: raw\n");
  EXPECT_THAT(LoadMapFile(bad_yaml, MapLoadOptions{}),
              StatusIs(Code::kInvalidArgument, bad_yaml + ": map mode 'raw'"));
  const std::string bad_pgm = Write("maps/c.pgm", "P5 4 4 255\n\x01");
  const std::string c_yaml = Write("maps/c.yaml", "image: c.pgm\nresolution: 0.05\n");
  EXPECT_THAT(LoadMapFile(c_yaml, MapLoadOptions{}),
              StatusIs(Code::kInvalidArgument, bad_pgm + ": PGM is truncated"));

  Write("maps/big.pgm", kPgm + std::string(33, ' '));  // 64 bytes
  const std::string big_yaml = Write("maps/big.yaml", "image: big.pgm\nresolution: 0.05\n");
  MapLoadOptions o;
  o.max_file_bytes = 40;  // the YAML fits, the image does not
  EXPECT_THAT(LoadMapFile(big_yaml, o), StatusIs(Code::kInvalidArgument,
                                                 "big.pgm is 64 bytes, above the limit "
                                                 "max_file_bytes = 40"));
}

bool SameMap(const OccupancyMap& a, const OccupancyMap& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.resolution() != b.resolution() ||
      a.origin().x != b.origin().x || a.origin().y != b.origin().y) {
    return false;
  }
  for (int r = 0; r < a.height(); ++r) {
    for (int c = 0; c < a.width(); ++c) {
      if (a.at(r, c) != b.at(r, c)) return false;
    }
  }
  return true;
}

TEST_F(MapFileTest, SaveThenLoadIsIdentity) {
  OccupancyMap map(37, 23, 0.05, {-12.345, 6.789000000000001});
  std::mt19937 rng(7);
  for (int r = 0; r < map.height(); ++r) {
    for (int c = 0; c < map.width(); ++c) map.set(r, c, static_cast<CellState>(rng() % 3));
  }
  const std::string yaml = (dir_ / "maps" / "saved.yaml").string();
  ASSERT_TRUE(SaveMapYamlPgm(map, yaml).ok());
  auto loaded = LoadMapFile(yaml, MapLoadOptions{});
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  EXPECT_TRUE(SameMap(map, *loaded));

  // The image on disk is upright: its first pixel is the map's top-left cell.
  std::ifstream in(dir_ / "maps" / "saved.pgm", std::ios::binary);
  const std::string pgm((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(pgm.size(), pgm.find("255\n") + 4 + 37 * 23);
  const uint8_t first = static_cast<uint8_t>(pgm[pgm.find("255\n") + 4]);
  const CellState top_left = map.at(22, 0);
  EXPECT_EQ(first, top_left == CellState::kFree ? 254 : top_left == CellState::kOccupied ? 0 : 205);
}

TEST_F(MapFileTest, SaveErrors) {
  OccupancyMap map(2, 2, 0.05, {0, 0});
  EXPECT_THAT(SaveMapYamlPgm(map, (dir_ / "m.pgm").string()),
              StatusIs(Code::kInvalidArgument, "must end in .yaml or .yml"));
  EXPECT_THAT(SaveMapYamlPgm(OccupancyMap(), (dir_ / "m.yaml").string()),
              StatusIs(Code::kInvalidArgument, "empty map"));
  EXPECT_FALSE(SaveMapYamlPgm(map, (dir_ / "no" / "such" / "dir" / "m.yaml").string()).ok());
}

// ---------------------------------------------------------------- shipped maps

TEST(SampleMaps, OfficeLoadsWithExpectedShape) {
  const std::string dir = absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/");
  auto office = LoadMapFile(dir + "sample_office.yaml", MapLoadOptions{});
  ASSERT_TRUE(office.ok()) << office.status();
  EXPECT_EQ(office->width(), 600);
  EXPECT_EQ(office->height(), 400);
  EXPECT_DOUBLE_EQ(office->resolution(), 0.05);
  int64_t occupied = 0, unknown = 0;
  for (int r = 0; r < office->height(); ++r) {
    for (int c = 0; c < office->width(); ++c) {
      occupied += office->at(r, c) == CellState::kOccupied;
      unknown += office->at(r, c) == CellState::kUnknown;
    }
  }
  // Mostly free floor, walls and furniture, unknown outside the building.
  EXPECT_GT(office->FreeAreaM2(), 300.0);
  EXPECT_LT(office->FreeAreaM2(), 600.0);
  EXPECT_GT(occupied, 10000);
  EXPECT_GT(unknown, 10000);

  auto furnished = LoadMapFile(dir + "sample_office_furnished.yaml", MapLoadOptions{});
  ASSERT_TRUE(furnished.ok()) << furnished.status();
  ASSERT_EQ(furnished->width(), office->width());
  ASSERT_EQ(furnished->height(), office->height());
  EXPECT_LT(furnished->CountFree(), office->CountFree());
  // Pixel aligned: the furnished map only adds obstacles.
  int64_t freed = 0;
  for (int r = 0; r < office->height(); ++r) {
    for (int c = 0; c < office->width(); ++c) {
      freed += furnished->IsFree(r, c) && !office->IsFree(r, c);
    }
  }
  EXPECT_EQ(freed, 0);
}

TEST(SampleMaps, SmallRoomsPng) {
  auto map =
      LoadMapFile(absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/small_rooms.yaml"), MapLoadOptions{});
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_EQ(map->width(), 200);
  EXPECT_EQ(map->height(), 150);
  EXPECT_GT(map->CountFree(), 200 * 150 / 3);
  EXPECT_EQ(map->at(0, 0), CellState::kOccupied);  // outer wall corner
}

}  // namespace
}  // namespace covplan
