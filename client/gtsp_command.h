// `covplan gtsp FILE [--time-limit S] [--seed N] [--threads N] [--effort E]`:
// solves a GTSPLIB instance in-process with the planner's GTSP solver and
// prints one JSON object on stdout:
//   {"instance": "...", "cost": 174, "tour": [1-based node ids], "time_s": 0.2,
//    "iterations": 1234, "stopped_early": false}
// Usage errors and unreadable/malformed instances go to stderr, exit code 2.
//
//   int rc = covplan::RunGtspCommand({"11eil51.gtsp", "--time-limit", "1"});
//
// Free of gRPC/protobuf so that it can also be linked into small tools.
#ifndef COVPLAN_CLIENT_GTSP_COMMAND_H_
#define COVPLAN_CLIENT_GTSP_COMMAND_H_

#include <string>
#include <vector>

namespace covplan {

// `args` exclude the program name and the word "gtsp". Returns the exit code.
int RunGtspCommand(const std::vector<std::string>& args);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_GTSP_COMMAND_H_
