// The work of the calls that continue a plan, once they run on a worker:
// Replan (new obstacles), Resume (from where the robot stopped and now
// stands) and a Drive session's first message (adopt the plan it names).
// The plan continued is found by id (retained, or rebuilt from the store
// after a restart) or rebuilt from an inline plan; the result is retained,
// persisted when its mission began on a stored map, and teaches the replan
// estimator. No gRPC here: handlers (server/replan_handlers.h,
// server/drive_handler.h) schedule and answer.
//
//   ReplanWork work(options, store, metrics, &engine, &archive, &progress, &admission);
//   absl::Status s = work.RunReplan(call, request, cancel, &response);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_REPLAN_WORK_H_
#define COVPLAN_SERVER_REPLAN_WORK_H_

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "planner/replan/replanner.h"
#include "server/admission.h"
#include "server/call_info.h"
#include "server/drive_host.h"
#include "server/fleet_missions.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/plan_archive.h"
#include "server/progress_log.h"
#include "server/service_options.h"

namespace covplan {

// The call name of a Drive session's replans (logs, metrics).
inline constexpr absl::string_view kDriveReplan = "Drive.Replan";

// One log line's summary of a replan reply.
std::string ReplanDetail(const v1::ReplanResponse& response);

class ReplanWork {
 public:
  // Every pointer outlives this.
  ReplanWork(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics,
             const PlanningEngine* engine, PlanArchive* archive, ProgressLog* progress,
             const SolveAdmission* admission, FleetMissions* missions = nullptr);

  absl::Status RunReplan(const CallInfo& call, const v1::ReplanRequest& request,
                         const StopToken& cancel, v1::ReplanResponse* response);
  absl::Status RunResume(const CallInfo& call, const v1::ResumeRequest& request,
                         const StopToken& cancel, v1::ReplanResponse* response);
  // The plan named by a Drive session's first message, found (plan_id) or
  // rebuilt and retained under a new id (inline), with its grid.
  absl::StatusOr<DriveHost::AdoptedPlan> AdoptPlan(const v1::DriveRequest& first,
                                                   const StopToken& stop,
                                                   const std::string& tenant_tag);

 private:
  // The plan a Replan / Resume / Drive continues, with the Plan request its
  // mission started with.
  struct ResolvedPlan {
    std::shared_ptr<const RetainedPlan> plan;
    v1::PlanRequest origin;
    bool has_origin = false;  // on a stored map: its replans are persisted
  };
  absl::Status ResolvePlan(const std::string& tenant_tag, const std::string& plan_id,
                           const v1::InlinePlan* inline_plan, const StopToken& stop,
                           ResolvedPlan* out);
  // The replan's options: method and seed, and a stop bounded by the call's
  // deadline (less the reply margin) or by the longest call without one.
  absl::StatusOr<ReplanOptions> OptionsFor(const CallInfo& call, v1::ReplanMethod method,
                                           uint64_t seed, const StopToken& cancel,
                                           absl::Time start) const;
  // Retains (and persists) a replan's result and fills the reply.
  // `mission_follows`: a fleet mission holding the old plan takes the new one.
  void KeepReplan(ReplanResult result, const ResolvedPlan& old, const std::string& tenant_tag,
                  v1::ReplanResponse* response, bool mission_follows);

  const ServiceOptions& options_;
  MapRepository* const store_;
  ServerMetrics* const metrics_;
  const PlanningEngine* const engine_;
  PlanArchive* const archive_;
  ProgressLog* const progress_;
  const SolveAdmission* const admission_;
  FleetMissions* const missions_;  // may be null: a fleet mission follows its robots' replans
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_REPLAN_WORK_H_
