// What a Drive session (server/drive_session.h) needs from the service that
// hosts it, and nothing more: adopt the plan its first message names, replan
// on a worker, queue work under the solve admission, keep the robot's
// progress, and count what the session's metrics show. The service side
// implements it (server/drive_handler.h); tests may fake it.
//
//   class Host final : public DriveHost { ... };
//   auto* session = new DriveSession(&host, context, &registry, "s-1", {tag, name});
//
// Thread-safety: implementations must be thread-safe; sessions call them
// from gRPC reactions and from workers.
#ifndef COVPLAN_SERVER_DRIVE_HOST_H_
#define COVPLAN_SERVER_DRIVE_HOST_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"

namespace covplan {

class DriveHost {
 public:
  // A plan named by a session's first message, found (plan_id) or rebuilt
  // and retained (inline), with its grid.
  struct AdoptedPlan {
    std::string plan_id;
    std::string map_id;
    std::shared_ptr<const Grid> grid;
  };

  // Who opened a session: its tenant's tag (quotas, the plans it may use)
  // and name (logs, metrics, messages); both empty without --token_file.
  struct Tenant {
    std::string tag;
    std::string name;
  };

  virtual ~DriveHost() = default;

  virtual absl::StatusOr<AdoptedPlan> AdoptPlan(const v1::DriveRequest& first,
                                                const StopToken& stop, const Tenant& tenant) = 0;
  // Runs one replan of a session (on a worker), logged and counted as a
  // "Drive.Replan" call with this request id.
  virtual absl::Status Replan(const std::string& request_id, const Tenant& tenant,
                              const v1::ReplanRequest& request, const StopToken& stop,
                              v1::ReplanResponse* response) = 0;
  // Runs `work` on the solve pool under the same admission bound as unary
  // solves, as a solve of `tenant` (its quota); non-OK
  // (and `work` dropped): RESOURCE_EXHAUSTED when the server or the
  // tenant's quota is full (saying which), UNAVAILABLE when it drains.
  virtual absl::Status SubmitSolve(const Tenant& tenant, std::function<void()> work) = 0;
  // The robot's latest progress on a plan, kept for Resume.
  virtual void RecordProgress(const std::string& plan_id, const v1::RobotProgress& progress) = 0;
  // The latest progress recorded for a plan (Drive, Replan), if any.
  virtual std::optional<v1::RobotProgress> RecordedProgress(const std::string& plan_id) {
    return std::nullopt;
  }
  // Obstacles a session's robot reported: shared with the other robots of
  // its fleet mission, if it has one. `plan_ids`: the robot's plans, newest
  // first (the mission holds one of them: a replan adopted since the report
  // may or may not have reached it yet). Called without any session's lock
  // held.
  virtual void ShareObstacles(const std::vector<std::string>& plan_ids,
                              const v1::Obstacles& obstacles) {}
  // True when someone watches the map's live events (server/live_events.h).
  virtual bool Watched(const std::string& map_id) { return false; }
  // A live event of a session's robot (map, session and plan set): the host
  // adds its fleet mission and the time and publishes it. Called under the
  // session's lock: it must never call into a session.
  virtual void Live(const v1::LiveEvent& event) {}
  // The session's robot drives `plan_id` now instead of `previous` (a
  // replan or a mission's plan pushed): its fleet mission follows.
  virtual void PlanAdopted(const std::string& previous, const std::string& plan_id) {}
  // A replan whose result a newer observation made stale.
  virtual void CountSuperseded() = 0;
  // Sets the open-sessions gauge (a session ended).
  virtual void UpdateSessionGauge() = 0;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_DRIVE_HOST_H_
