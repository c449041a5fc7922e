// `covplan simulate --server`: a PlanSource (planner/sim) that asks a
// covplan server for the plans. The known map is registered with PutMap and
// planned with Plan; the run is one Drive session, each replan an
// observation on it (a greedy-detour retry overrides the session's method
// for that observation). Compute time therefore includes the network and the
// server's queue, so the simulator is also a load and fault test of the
// session.
//
//   ASSIGN_OR_RETURN(std::unique_ptr<PlanSource> src,
//                    ConnectServerPlanSource("127.0.0.1:50051", "maps/sample_office.yaml", {},
//                    options));
//   ASSIGN_OR_RETURN(SimulationResult r, Simulate(known, truth, options, src.get()));
//
// Thread-safety: one simulation at a time.
#ifndef COVPLAN_CLIENT_SIMULATE_REMOTE_H_
#define COVPLAN_CLIENT_SIMULATE_REMOTE_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "client/simulate_command.h"
#include "planner/sim/simulator.h"

namespace covplan {

// A RemotePlanSourceFactory (client/simulate_command.h).
absl::StatusOr<std::unique_ptr<PlanSource>> ConnectServerPlanSource(
    const Connection& server, const std::string& known_map_path, const SimulateRemoteFlags& flags,
    const SimulationOptions& options);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_SIMULATE_REMOTE_H_
