#include "tests/testing/test_maps.h"

#include <random>

#include "absl/strings/str_cat.h"

namespace covplan::testing {

std::string AsciiToPgm(const std::vector<std::string>& rows, int k) {
  const int height = static_cast<int>(rows.size()) * k;
  const int width = rows.empty() ? 0 : static_cast<int>(rows[0].size()) * k;
  std::string pgm = absl::StrCat("P5\n", width, " ", height, "\n255\n");
  for (const std::string& row : rows) {
    for (int dy = 0; dy < k; ++dy) {
      for (char c : row) {
        const char value = c == '.'   ? static_cast<char>(254)
                           : c == '#' ? 0
                                      : static_cast<char>(205);
        pgm.append(static_cast<size_t>(k), value);
      }
    }
  }
  return pgm;
}

v1::Map RasterMap(const std::string& image, double resolution) {
  v1::Map map;
  map.mutable_raster()->set_image(image);
  map.mutable_raster()->set_resolution(resolution);
  return map;
}

const std::vector<std::string>& TwoRooms() {
  static const std::vector<std::string> rows = {
      "############",  //
      "#....#.....#",  //
      "#....#.....#",  //
      "#..........#",  //
      "#....#..#..#",  //
      "#....#.....#",  //
      "#....#.....#",  //
      "############",
  };
  return rows;
}

std::vector<std::string> PillarField(int cols, int rows, int pillars, unsigned seed) {
  std::vector<std::string> field(rows, std::string(cols, '.'));
  for (int c = 0; c < cols; ++c) field[0][c] = field[rows - 1][c] = '#';
  for (int r = 0; r < rows; ++r) field[r][0] = field[r][cols - 1] = '#';
  std::mt19937 random(seed);
  for (int i = 0; i < pillars; ++i) {
    const int r = 2 + static_cast<int>(random() % (rows - 5));
    const int c = 2 + static_cast<int>(random() % (cols - 5));
    const int h = 1 + static_cast<int>(random() % 2);
    const int w = 1 + static_cast<int>(random() % 2);
    for (int dr = 0; dr < h; ++dr) {
      for (int dc = 0; dc < w; ++dc) field[r + dr][c + dc] = '#';
    }
  }
  return field;
}

v1::PlanRequest PlanRequestFor(const std::string& map_id, double tool_width_m) {
  v1::PlanRequest request;
  request.set_map_id(map_id);
  request.mutable_robot()->set_tool_width_m(tool_width_m);
  request.set_time_limit_s(0.5);
  request.set_seed(7);
  return request;
}

}  // namespace covplan::testing
