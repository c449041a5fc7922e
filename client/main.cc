// covplan: the command-line client.
//
//   covplan plan --map FILE [--resolution M] [--tool-width M] [--local | --server HOST:PORT]
//                [--out plan.json] [--svg plan.svg] ...
//   covplan replan --server HOST:PORT --plan-id P --waypoint K --at X,Y --obstacle "x,y ..."
//   covplan resume --server HOST:PORT --plan-id P --at X,Y[,THETA] [--distance D]
//   covplan load --server HOST:PORT --map FILE [--concurrency N] [--duration S] [--deadline-ms D]
//   covplan gtsp ...
//   covplan simulate --map KNOWN (--true-map TRUE | --clutter PCT) [--method auto] [--local |
//   --server H:P] covplan compare --map FILE [--algorithms oarp,stc] [--tool-width M] [--json
//   out.json] covplan partition --map FILE [--resolution M] [--tool-width M] [--solver NAME]
//
// Subcommands parse their own flags (client/args.h); no global flags.
#include <cstdio>
#include <string>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "client/compare_command.h"
#include "client/gtsp_command.h"
#include "client/health_command.h"
#include "client/load_command.h"
#include "client/partition_command.h"
#include "client/plan_command.h"
#include "client/plan_exports.h"
#include "client/replan_command.h"
#include "client/simulate_command.h"
#include "client/simulate_fleet.h"
#include "client/simulate_remote.h"

namespace {

constexpr char kUsage[] =
    "usage: covplan <command> [flags]\n"
    "commands:\n"
    "  plan   plan a coverage path (--local or through a server); writes plan.json / SVG\n"
    "  replan report new obstacles for a retained plan; get the replanned remainder\n"
    "  resume continue an interrupted plan from where the robot is now\n"
    "  load   load-test a server's Plan method; prints one JSON object\n"
    "  gtsp   solve a GTSPLIB instance with the tour solver\n"
    "  simulate  drive a plan through the true map, replanning on new obstacles; prints JSON\n"
    "  compare   plan one map with several planners and print one table (and JSON)\n"
    "  partition time the minimum rank partition alone on a map (one JSON object)\n"
    "  health exit 0 when a server's gRPC health check reports SERVING\n"
    "  export a plan.json as GeoJSON, CSV waypoints or a nav_msgs/Path JSON\n"
    "Run 'covplan <command> --help' for its flags.\n";

}  // namespace

int main(int argc, char** argv) {
  // As in covplan-server: no abseil deadlock detection (Debian builds it
  // without NDEBUG) outside the tests.
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);
  if (argc < 2) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  const std::string command = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  if (command == "plan") return covplan::RunPlanCommand(args);
  if (command == "replan") return covplan::RunReplanCommand(args);
  if (command == "resume") return covplan::RunResumeCommand(args);
  if (command == "load") return covplan::RunLoadCommand(args);
  if (command == "gtsp") return covplan::RunGtspCommand(args);
  if (command == "simulate")
    return covplan::RunSimulateCommand(args, &covplan::ConnectServerPlanSource,
                                       &covplan::FleetSimulation());
  if (command == "compare") return covplan::RunCompareCommand(args);
  if (command == "partition") return covplan::RunPartitionCommand(args);
  if (command == "health") return covplan::RunHealthCommand(args);
  if (command == "export") return covplan::RunExportCommand(args);
  if (command == "--help" || command == "-h" || command == "help") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  std::fprintf(stderr, "covplan: unknown command '%s'\n%s", command.c_str(), kUsage);
  return 2;
}
