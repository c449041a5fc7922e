// `covplan partition --map FILE [--resolution M] [--tool-width M] [--solver NAME]
// [--repeat N]`: the minimum rank partition alone, in this process, on the
// coverage grid `covplan plan` would partition (same map reading, same grid
// options), and prints one JSON object:
//   {"map": "...", "solver": "pushrelabel", "tool_width_m": 0.8, "rows": 40,
//    "cols": 60, "free_cells": 1822, "num_ranks": 84, "partition_ms": 1.9,
//    "partition_ms_runs": [...], "grid_ms": 12.0}
// partition_ms is the median of N timed runs (default 1) of the solver on a
// ready grid; grid_ms the time to build the grid from the map. Every run must
// give the same rank count (all solvers are exact).
//
//   absl::StatusOr<std::string> json = PartitionCommandJson({"--map", "office.yaml"});
//
// Thread-safety: runs on the calling thread.
#ifndef COVPLAN_CLIENT_PARTITION_COMMAND_H_
#define COVPLAN_CLIENT_PARTITION_COMMAND_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace covplan {

// The JSON text (no trailing newline); InvalidArgument for bad flags or maps.
absl::StatusOr<std::string> PartitionCommandJson(const std::vector<std::string>& args);

// `args` exclude the program name and the word "partition". Exit code.
int RunPartitionCommand(const std::vector<std::string>& args);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_PARTITION_COMMAND_H_
