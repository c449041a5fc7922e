// `covplan simulate`: drive an OARP plan of the known map through the true
// map (a second map file, or the known one with random clutter), replanning
// with OARP-Replan whenever the sensor finds new obstacles on the path, and
// print one JSON object with the run's figures and the offline lower bound
// (OARP planned on the true map).
//
//   covplan simulate --map maps/sample_office.yaml --true-map maps/sample_office_furnished.yaml
//       --method auto --local --svg run.svg
//   covplan simulate --map lab_ipa.png --resolution 0.05 --free-thresh 0.021 --clutter 10 --seed 3
//
// Only in-process simulation (--local) exists: a server-side run needs the
// streaming replanning session, which the server does not offer yet.
// This unit has no gRPC or protobuf dependency (the simulator tests build it).
// Thread-safety: not applicable (command entry points).
#ifndef COVPLAN_CLIENT_SIMULATE_COMMAND_H_
#define COVPLAN_CLIENT_SIMULATE_COMMAND_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace covplan {

// Returns the process exit code; the JSON goes to stdout, errors to stderr.
int RunSimulateCommand(const std::vector<std::string>& args);

// Parses the flags, runs the simulation and the offline lower bound, writes
// --svg if asked, and returns the JSON object RunSimulateCommand prints.
// InvalidArgument for bad flags or maps.
absl::StatusOr<std::string> SimulateCommandJson(const std::vector<std::string>& args);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_SIMULATE_COMMAND_H_
