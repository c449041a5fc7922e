// Wall-clock margins in tests that check a deadline or a cancellation is
// honoured: a sanitizer build runs about three times slower, and the suite
// runs two tests at a time beside it, so its margins are four times wider.
// The property is the same; only the slack scales.
//
//   EXPECT_LT(wall_s, deadline_s + 0.100 * testing::kTimingSlowdown);
#ifndef COVPLAN_TESTS_TESTING_TIMING_H_
#define COVPLAN_TESTS_TESTING_TIMING_H_

namespace covplan::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr double kTimingSlowdown = 4.0;
#else
inline constexpr double kTimingSlowdown = 1.0;
#endif

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_TIMING_H_
