// Test-only helpers: small maps written as ASCII art, encoded as the PGM
// bytes a client would send, and Map protos around them.
//
//   std::string pgm = AsciiToPgm({"#####", "#...#", "#####"}, /*pixels_per_char=*/4);
//   v1::Map map = RasterMap(pgm, /*resolution=*/0.1);
//
// Thread-safety: stateless.
#ifndef COVPLAN_TESTS_TESTING_TEST_MAPS_H_
#define COVPLAN_TESTS_TESTING_TEST_MAPS_H_

#include <string>
#include <vector>

#include "covplan/v1/covplan.pb.h"

namespace covplan::testing {

// Rows top-down (the first string is the top of the picture); '.' free,
// '#' occupied, '?' unknown. Each character becomes a k x k pixel block.
std::string AsciiToPgm(const std::vector<std::string>& rows, int pixels_per_char);

// A bare-image map with an explicit resolution.
v1::Map RasterMap(const std::string& image, double resolution);

// Two rooms joined by a door, with a pillar: 12 x 8 characters.
const std::vector<std::string>& TwoRooms();

// A walled field of `cols` x `rows` characters with `pillars` random 1-2
// character obstacles (seeded): hundreds of ranks, a long tour search.
std::vector<std::string> PillarField(int cols, int rows, int pillars, unsigned seed);

// A PlanRequest for `map_id` with the given tool width.
v1::PlanRequest PlanRequestFor(const std::string& map_id, double tool_width_m);

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_TEST_MAPS_H_
