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
// --local (default) plans and replans in process; --server HOST:PORT runs the
// same simulation against a server through a Drive session
// (client/simulate_remote.h).
// Thread-safety: not applicable (command entry points).
#ifndef COVPLAN_CLIENT_SIMULATE_COMMAND_H_
#define COVPLAN_CLIENT_SIMULATE_COMMAND_H_

#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/args.h"
#include "client/connection.h"
#include "planner/grid/occupancy_map.h"
#include "planner/sim/simulator.h"

namespace covplan {

// What a run through a server needs of the flags: the map flags, as given
// (the server is sent the map file itself), and --watch.
struct SimulateRemoteFlags {
  std::optional<double> resolution, free_thresh, occupied_thresh;
  bool negate = false;
  // --watch SPEED: the robot drives at SPEED times real time and reports its
  // progress on the Drive session (at most 20 times a second), so a person
  // can watch it in the web console; 0 = as fast as it computes, unreported.
  double watch_speed = 0.0;
};
// Makes the PlanSource of --server HOST:PORT (with the connection flags,
// client/connection.h) for the known map file. The
// covplan binary passes client/simulate_remote.h's; without one, --server is
// refused. (This unit stays free of gRPC: the simulator tests compile it.)
using RemotePlanSourceFactory = std::function<absl::StatusOr<std::unique_ptr<PlanSource>>(
    const Connection& server, const std::string& known_map_path, const SimulateRemoteFlags& flags,
    const SimulationOptions& options)>;

// A fleet of simulated robots (--robot ... or --robots K, --fail-robot ...):
// the flags it adds to `covplan simulate`, whether the parsed flags ask for
// a fleet, and the run, given the maps and the single-robot options
// simulate parsed; `run` returns the text to print. The covplan binary
// passes client/simulate_fleet.h's; without one the fleet flags are unknown.
struct FleetSimulateHook {
  std::set<std::string> value_flags, repeatable_flags;
  std::function<bool(const ParsedArgs&)> wanted;
  std::function<absl::StatusOr<std::string>(
      const ParsedArgs& args, const OccupancyMap& known, const OccupancyMap& truth,
      const std::string& truth_name, const SimulationOptions& options)>
      run;
};

// Returns the process exit code; the JSON goes to stdout, errors to stderr.
int RunSimulateCommand(const std::vector<std::string>& args,
                       const RemotePlanSourceFactory& remote = nullptr,
                       const FleetSimulateHook* fleet = nullptr);

// Parses the flags, runs the simulation and the offline lower bound, writes
// --svg if asked, and returns the JSON object RunSimulateCommand prints (with
// `fleet` and fleet flags: what fleet->run returns). InvalidArgument for bad
// flags or maps.
absl::StatusOr<std::string> SimulateCommandJson(const std::vector<std::string>& args,
                                                const RemotePlanSourceFactory& remote = nullptr,
                                                const FleetSimulateHook* fleet = nullptr);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_SIMULATE_COMMAND_H_
