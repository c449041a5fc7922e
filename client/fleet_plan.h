// `covplan plan --robot ... --robot ...` (or `--robots K`): several robots
// on one site, planned by PlanFleet (planner/fleet/fleet_planner.h): with
// --local in this process on the CLI's LocalEngine, else by a server's
// PlanFleet RPC. The plan flags
// give the site, the planner and its options, the budget and the robot model
// every robot shares (tool width, speed, acceleration, turn rate, --end,
// battery); each --robot gives one robot's id and start pose.
//
//   --robot [ID=]X,Y[,THETA]   one robot (repeatable; ids default to r1, r2, ...)
//   --robots K                 K robots without a start pose (the planner spreads them)
//   --division makespan|equal_area   (default makespan)
//   --clearance M              the safety report's distance (default: the tool width)
//
// Prints the fleet's figures (FormatFleetSummary), writes --out as a fleet
// JSON (the figures and, per robot, its plan in plan.json's form) and --svg
// as one picture of every robot's path (RenderFleetSvg).
//
// Thread-safety: not applicable (command helpers).
#ifndef COVPLAN_CLIENT_FLEET_PLAN_H_
#define COVPLAN_CLIENT_FLEET_PLAN_H_

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "client/args.h"
#include "client/connection.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/engine/engine.h"
#include "planner/fleet/fleet_request.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/svg.h"
#include "planner/tour/gtsp/gtsp.h"

namespace covplan {

// What the fleet flags ask for; each robot's model is filled in later from
// the plan flags (MakeFleetRequest).
struct FleetFlags {
  std::vector<FleetRobot> robots;  // id and, from --robot, the start pose
  FleetDivision division = FleetDivision::kMakespan;
  double clearance_m = 0.0;  // 0: the tool width
};

// The value flags (--robots, --division, --clearance) and the repeatable
// flag (--robot) fleet planning adds to `covplan plan`.
std::set<std::string> FleetValueFlags();
inline constexpr char kRobotFlag[] = "robot";

// "[ID=]X,Y[,THETA]" as robot number `index` (0-based; its default id is
// r<index + 1>). InvalidArgument naming --robot otherwise.
absl::StatusOr<FleetRobot> ParseRobotFlag(const std::string& text, size_t index);

// nullopt when neither --robot nor --robots is given (and then --division
// and --clearance are refused). InvalidArgument naming the flag.
absl::StatusOr<std::optional<FleetFlags>> ParseFleetFlags(const ParsedArgs& a);

// The fleet request: `base` (the plan flags, converted) with, per robot,
// base's robot model and battery and the robot's own start. Without an
// explicit end pose each robot returns to its own start.
FleetRequest MakeFleetRequest(const PlanRequest& base, const FleetFlags& flags);

struct LocalFleetRun {
  FleetRequest request;
  FleetPlan plan;
  std::string map_id;
};

// Plans the fleet in this process; `request` carries the map inline.
absl::StatusOr<LocalFleetRun> PlanFleetLocally(const v1::PlanRequest& request,
                                               const FleetFlags& flags, const EngineLimits& limits,
                                               int num_threads = 1,
                                               std::optional<GtspEffort> tour_effort = {});

// The human summary: one line per robot, then the fleet's figures.
std::string FormatFleetSummary(const FleetRequest& request, const FleetPlan& plan);

// The fleet JSON: the fleet's figures, the safety report and per robot its
// figures and its plan as plan.json writes a single plan (PlanToJson).
absl::StatusOr<std::string> FleetToJson(const LocalFleetRun& run, const std::string& map_path);

// Every robot's path in one picture; `map` may be null (polygon maps).
std::string FleetToSvg(const LocalFleetRun& run, const OccupancyMap* map, const SvgZones& zones);

// The whole `plan` run for a fleet: plan, print, write `out` and `svg`.
struct FleetRunOptions {
  std::string map_path;
  std::optional<std::string> out, svg;
  int threads = 1;
  std::optional<GtspEffort> tour_effort;
};
absl::Status RunLocalFleet(const v1::PlanRequest& request, const FleetFlags& flags,
                           const EngineLimits& limits, const FleetRunOptions& options);

// The same through a server: stores the map (PutMap), calls PlanFleet,
// prints the summary with the mission id, writes --out as the server's
// PlanFleetResponse in protobuf's JSON mapping (the mission id and each
// robot's plan_id, which Replan, Drive, Resume and GetPlan take) and --svg.
// `request` carries the map inline.
absl::Status RunRemoteFleet(const Connection& server, const v1::PlanRequest& request,
                            const FleetFlags& flags, const EngineLimits& limits,
                            const FleetRunOptions& options, std::optional<absl::Duration> timeout);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_FLEET_PLAN_H_
