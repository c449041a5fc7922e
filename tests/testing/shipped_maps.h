// Test helper: loads a map shipped in maps/ (e.g. "sample_office.yaml").
// Thread-safety: stateless.
#ifndef COVPLAN_TESTS_TESTING_SHIPPED_MAPS_H_
#define COVPLAN_TESTS_TESTING_SHIPPED_MAPS_H_

#include <string>

#include "gtest/gtest.h"
#include "planner/grid/map_io.h"

namespace covplan::testing {

inline OccupancyMap LoadShippedMap(const std::string& name) {
  absl::StatusOr<OccupancyMap> map =
      LoadMapFile(std::string(COVPLAN_SOURCE_DIR) + "/maps/" + name, MapLoadOptions());
  EXPECT_TRUE(map.ok()) << name << ": " << map.status();
  return map.ok() ? *std::move(map) : OccupancyMap();
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_SHIPPED_MAPS_H_
