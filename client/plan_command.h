// `covplan plan`: plan a map locally (--local) or through a server, print a
// summary, write plan.json (the Plan response as canonical protobuf JSON) and
// optionally an SVG.
//
//   covplan plan --map maps/sample_office.yaml --tool-width 0.8 --server 127.0.0.1:50051
//       --out plan.json --svg plan.svg
//
// With --robot X,Y (repeated) or --robots K, and --local, it plans a fleet
// instead (client/fleet_plan.h): PlanFleet, the fleet's figures, a fleet JSON
// and one SVG of every robot.
//
// Thread-safety: not applicable (command entry points).
#ifndef COVPLAN_CLIENT_PLAN_COMMAND_H_
#define COVPLAN_CLIENT_PLAN_COMMAND_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "api/convert.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/tour/gtsp/gtsp.h"

namespace covplan {

// Returns the process exit code; errors go to stderr.
int RunPlanCommand(const std::vector<std::string>& args);

// Plans in-process through the same convert code the server uses, so --local
// and server mode produce the same JSON (up to plan_id and timings).
// `num_threads`: worker threads of the planning core (server: 1 per call);
// `tour_effort` (OARP only, not in the API): the tour search's effort.
absl::StatusOr<v1::PlanResponse> PlanLocally(const v1::PlanRequest& request,
                                             const EngineLimits& limits, int num_threads = 1,
                                             std::optional<GtspEffort> tour_effort = std::nullopt);

// The human summary printed to stdout.
std::string FormatPlanSummary(const v1::PlanResponse& response);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_PLAN_COMMAND_H_
