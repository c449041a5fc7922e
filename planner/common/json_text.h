// JSON text pieces for the writers that print a fixed shape themselves
// (exports, the CLI's reports): a string literal and a number that reads back
// to the same double.
//
//   out += "{\"id\": " + JsonString(id) + ", \"x\": " + JsonNumber(x) + "}";
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_PLANNER_COMMON_JSON_TEXT_H_
#define COVPLAN_PLANNER_COMMON_JSON_TEXT_H_

#include <string>

namespace covplan {

// `s` as a JSON string literal (quotes, backslashes and control characters escaped).
std::string JsonString(const std::string& s);

// The shortest decimal that reads back to `v` (std::to_chars); null when not finite.
std::string JsonNumber(double v);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_COMMON_JSON_TEXT_H_
