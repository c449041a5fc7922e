// Test helpers for map I/O: a StatusIs matcher (Debian's abseil ships none)
// and a compact picture of an OccupancyMap for exact assertions.
//
//   EXPECT_THAT(LoadMapFile(p, opt), StatusIs(absl::StatusCode::kNotFound, p));
//   EXPECT_THAT(TopDown(map), ElementsAre("#.?", "..."));
//
// Thread-safety: stateless.
#ifndef COVPLAN_TESTS_GRID_MAP_TEST_UTIL_H_
#define COVPLAN_TESTS_GRID_MAP_TEST_UTIL_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "planner/grid/occupancy_map.h"

namespace covplan::testing {

inline const absl::Status& GetStatus(const absl::Status& s) { return s; }
template <typename T>
const absl::Status& GetStatus(const absl::StatusOr<T>& s) {
  return s.status();
}

// Matches a Status / StatusOr whose code is `code` and whose message contains
// `substring`.
MATCHER_P2(StatusIs, code, substring,
           absl::StrCat("has status code ", absl::StatusCodeToString(code),
                        " and a message containing \"", std::string(substring), "\"")) {
  const absl::Status& s = GetStatus(arg);
  *result_listener << "status is " << s;
  return s.code() == code && s.message().find(substring) != absl::string_view::npos;
}

// One string per row, *top row (largest y) first*: '.' free, '#' occupied,
// '?' unknown.
inline std::vector<std::string> TopDown(const OccupancyMap& map) {
  std::vector<std::string> rows;
  for (int r = map.height() - 1; r >= 0; --r) {
    std::string row;
    for (int c = 0; c < map.width(); ++c) {
      const CellState s = map.at(r, c);
      row.push_back(s == CellState::kFree ? '.' : s == CellState::kOccupied ? '#' : '?');
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_GRID_MAP_TEST_UTIL_H_
