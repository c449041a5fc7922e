// `covplan replan`: report new obstacles for a plan a server retains and get
// the replanned remainder (the Replan RPC); prints a summary, writes the
// new plan as plan.json and optionally an SVG.
//
//   covplan replan --server 127.0.0.1:50051 --plan-id p-... --waypoint 40 --at 3.2,4.0
//       --obstacle "9,9.2 10.2,9.2 10.2,10 9,10" --out replanned.json
//
// Thread-safety: not applicable (command entry point).
#ifndef COVPLAN_CLIENT_REPLAN_COMMAND_H_
#define COVPLAN_CLIENT_REPLAN_COMMAND_H_

#include <string>
#include <vector>

#include "covplan/v1/covplan.pb.h"

namespace covplan {

// Returns the process exit code; errors go to stderr.
int RunReplanCommand(const std::vector<std::string>& args);
// `covplan resume` (the Resume RPC): continue plan P from where the robot is
// now, over what it had not covered.
int RunResumeCommand(const std::vector<std::string>& args);

// The human summary printed to stdout.
std::string FormatReplanSummary(const v1::ReplanResponse& response);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_REPLAN_COMMAND_H_
