// Wall-clock margins in tests that check a deadline or a cancellation is
// honoured: a sanitizer build runs about three times slower, and the suite
// runs two tests at a time beside it, so its margins are four times wider.
// The property is the same; only the slack scales.
//
//   EXPECT_LT(wall_s, deadline_s + 0.100 * testing::kTimingSlowdown);
#ifndef COVPLAN_TESTS_TESTING_TIMING_H_
#define COVPLAN_TESTS_TESTING_TIMING_H_

#include <string>

namespace covplan::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr double kTimingSlowdown = 4.0;
#else
inline constexpr double kTimingSlowdown = 1.0;
#endif

// The server's --deadline_margin_ms (the part of a deadline kept for sending
// the reply; 25 ms by default), scaled alike: a sanitized server needs longer
// to notice its stop and send, so a reply due at the deadline arrives in time.
inline std::string ReplyMarginFlag() {
  return "--deadline_margin_ms=" + std::to_string(static_cast<int>(25 * kTimingSlowdown));
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_TIMING_H_
