// `covplan simulate` with a fleet (planner/sim/fleet_simulator.h): the fleet
// flags of `covplan plan` (client/fleet_plan.h: --robot [ID=]X,Y[,THETA]...
// or --robots K, --division, --clearance) plus --fail-robot ID@SECONDS
// (repeatable) and --out FILE. The known and true maps, the robot model,
// planner, budget, sensor and replanning flags are simulate's own.
//
//   covplan simulate --map maps/sample_office.yaml --true-map maps/sample_office_furnished.yaml
//       --robot a=1.5,1.5 --robot b=20,1.5 --robot c=10,10 --fail-robot b@200
//       --out fleet_run.json --svg fleet_run.svg
//
// Prints per robot its swept cells and finish time, the makespan, per failure
// the redivision's estimated makespan against the one achieved after it, and
// the reachable cells left unswept; --out writes the same as JSON, --svg the
// driven paths (RenderFleetSvg) on the true map.
//
// Thread-safety: not applicable (command helpers).
#ifndef COVPLAN_CLIENT_SIMULATE_FLEET_H_
#define COVPLAN_CLIENT_SIMULATE_FLEET_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/simulate_command.h"
#include "planner/sim/fleet_simulator.h"

namespace covplan {

// The hook RunSimulateCommand / SimulateCommandJson take for fleets.
const FleetSimulateHook& FleetSimulation();

// "ID@SECONDS" of --fail-robot; InvalidArgument naming the flag.
absl::StatusOr<RobotFailure> ParseFailRobot(const std::string& text);

// The human summary of a fleet run.
std::string FormatFleetSimulation(const FleetSimulationResult& r);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_SIMULATE_FLEET_H_
