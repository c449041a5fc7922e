#include "server/replan_work.h"

#include <optional>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api/convert.h"
#include "planner/common/status_macros.h"
#include "server/map_sources.h"
#include "server/not_found.h"
#include "server/tenant_tokens.h"

namespace covplan {

std::string ReplanDetail(const v1::ReplanResponse& r) {
  return absl::StrFormat("plan=%s method=%s encounters=%d detours=%d new_ranks=%d",
                         r.plan().plan_id(), r.replan().method(), r.replan().num_encounters(),
                         r.replan().greedy_detours_size(), r.replan().new_ranks());
}

ReplanWork::ReplanWork(const ServiceOptions& options, MapRepository* store, ServerMetrics* metrics,
                       const PlanningEngine* engine, PlanArchive* archive, ProgressLog* progress,
                       const SolveAdmission* admission, FleetMissions* missions)
    : options_(options),
      store_(store),
      metrics_(metrics),
      engine_(engine),
      archive_(archive),
      progress_(progress),
      admission_(admission),
      missions_(missions) {}

absl::StatusOr<ReplanOptions> ReplanWork::OptionsFor(const CallInfo& call, v1::ReplanMethod method,
                                                     uint64_t seed, const StopToken& cancel,
                                                     absl::Time start) const {
  ASSIGN_OR_RETURN(ReplanMethod replan_method, ReplanMethodFromProto(method));
  ReplanOptions options;
  options.method = replan_method;
  options.seed = seed;
  // Never late: the call's deadline (less the reply margin) bounds the work;
  // the time to each encounter bounds it further inside the replanner.
  options.stop = call.deadline != absl::InfiniteFuture()
                     ? cancel.WithEarlierDeadline(call.deadline - options_.deadline_margin)
                     : cancel.WithEarlierDeadline(start + options_.max_request_time);
  return options;
}

absl::Status ReplanWork::RunReplan(const CallInfo& call, const v1::ReplanRequest& request,
                                   const StopToken& cancel, v1::ReplanResponse* response) {
  const absl::Time start = absl::Now();
  if (admission_->drain_cut())
    return absl::UnavailableError("server is shutting down; retry on another");
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  if (call.deadline != absl::InfiniteFuture() &&
      call.deadline - options_.deadline_margin <= start) {
    return absl::DeadlineExceededError(
        absl::StrFormat("deadline of %d ms left no time to replan (it waited %d ms for a worker)",
                        absl::ToInt64Milliseconds(call.deadline - call.start),
                        absl::ToInt64Milliseconds(start - call.start)));
  }
  ASSIGN_OR_RETURN(RobotProgress progress, ProgressFromProto(request.progress()));
  ASSIGN_OR_RETURN(ReplanOptions options,
                   OptionsFor(call, request.method(), request.seed(), cancel, start));
  ResolvedPlan old;
  RETURN_IF_ERROR(
      ResolvePlan(call.tenant_tag, request.plan_id(),
                  request.plan_ref_case() == v1::ReplanRequest::kPlan ? &request.plan() : nullptr,
                  options.stop, &old));
  ASSIGN_OR_RETURN(ReplanResult result,
                   covplan::Replan(*old.plan, progress, ObstaclesFromProto(request.obstacles()),
                                   options, archive_->mutable_estimator()));
  if (request.plan_ref_case() == v1::ReplanRequest::kPlanId)
    progress_->Record(request.plan_id(), request.progress());
  KeepReplan(std::move(result), old, call.tenant_tag, response,
             /*mission_follows=*/absl::string_view(call.method) != kDriveReplan);
  return absl::OkStatus();
}

absl::Status ReplanWork::RunResume(const CallInfo& call, const v1::ResumeRequest& request,
                                   const StopToken& cancel, v1::ReplanResponse* response) {
  const absl::Time start = absl::Now();
  if (cancel.ShouldStop()) return absl::CancelledError("call cancelled before it started");
  if (call.deadline != absl::InfiniteFuture() &&
      call.deadline - options_.deadline_margin <= start) {
    return absl::DeadlineExceededError("the deadline left no time to resume");
  }
  if (request.plan_id().empty())
    return absl::InvalidArgumentError("plan_id: required (the interrupted plan)");
  if (!request.has_pose())
    return absl::InvalidArgumentError("pose: required (where the robot is now)");
  const Pose2 pose{request.pose().x(), request.pose().y(), request.pose().theta()};
  ASSIGN_OR_RETURN(ReplanOptions options,
                   OptionsFor(call, request.method(), request.seed(), cancel, start));
  ResolvedPlan old;
  RETURN_IF_ERROR(ResolvePlan(call.tenant_tag, request.plan_id(), nullptr, options.stop, &old));
  v1::RobotProgress at;
  std::string source;
  if (request.has_progress()) {
    at = request.progress();
    source = "request";
  } else if (std::optional<v1::RobotProgress> recorded = progress_->Recorded(request.plan_id())) {
    at = *recorded;
    source = "recorded";
  } else {
    at.set_distance_m(0.0);  // nothing reported: nothing counted as covered
    source = "plan_start";
  }
  ASSIGN_OR_RETURN(RobotProgress progress, ProgressFromProto(at));
  double rejoin_m = 0.0;
  absl::StatusOr<ReplanResult> result =
      covplan::Resume(*old.plan, progress, pose, ObstaclesFromProto(request.obstacles()), options,
                      archive_->mutable_estimator(), &rejoin_m);
  if (!result.ok()) {
    if (source == "request" || !absl::IsInvalidArgument(result.status()) ||
        absl::StartsWith(result.status().message(), "pose")) {
      return result.status();
    }
    return absl::InvalidArgumentError(
        absl::StrCat("the progress recorded for this plan (", source,
                     ") no longer fits it: ", result.status().message()));
  }
  progress_->Record(request.plan_id(), at);
  KeepReplan(std::move(*result), old, call.tenant_tag, response, /*mission_follows=*/true);
  response->mutable_replan()->set_progress_source(source);
  response->mutable_replan()->set_rejoin_m(rejoin_m);
  return absl::OkStatus();
}

absl::Status ReplanWork::ResolvePlan(const std::string& tenant_tag, const std::string& plan_id,
                                     const v1::InlinePlan* inline_plan, const StopToken& stop,
                                     ResolvedPlan* out) {
  if (inline_plan == nullptr) {
    if (plan_id.empty()) return absl::InvalidArgumentError("needs plan_id or an inline plan");
    if (!OwnsPlan(tenant_tag, plan_id)) return PlanNotFound(plan_id);
    out->plan = archive_->Find(plan_id, stop, &out->origin);
    if (out->plan == nullptr) return PlanNotFound(plan_id);
    out->has_origin = out->origin.map_ref_case() == v1::PlanRequest::kMapId;
    return absl::OkStatus();
  }
  const v1::PlanRequest& pr = inline_plan->request();
  std::string map_id;
  std::shared_ptr<const v1::Map> inline_map;
  if (pr.map_ref_case() == v1::PlanRequest::kMapId) {
    RETURN_IF_ERROR(ValidateMapId(pr.map_id()));
    map_id = pr.map_id();
    if (!OwnsMap(tenant_tag, map_id)) return MapNotFound(map_id);
  } else if (pr.map_ref_case() == v1::PlanRequest::kMap) {
    map_id = ComputeMapId(pr.map());
    inline_map = std::make_shared<const v1::Map>(pr.map());
  } else {
    return absl::InvalidArgumentError("plan.request needs map_id or an inline map");
  }
  ASSIGN_OR_RETURN(
      RetainedPlan rebuilt,
      RetainedPlanFromInline(*inline_plan, *engine_,
                             MapSourceFor(store_, options_.limits, map_id, inline_map), stop));
  out->plan = std::make_shared<const RetainedPlan>(std::move(rebuilt));
  out->origin = pr;
  out->has_origin = pr.map_ref_case() == v1::PlanRequest::kMapId;
  return absl::OkStatus();
}

void ReplanWork::KeepReplan(ReplanResult result, const ResolvedPlan& old,
                            const std::string& tenant_tag, v1::ReplanResponse* response,
                            bool mission_follows) {
  auto retained = std::make_shared<RetainedPlan>();
  retained->plan_id = NewPlanId(tenant_tag);
  retained->map_id = old.plan->map_id;
  retained->plan = std::move(result.plan);
  retained->area = result.area;
  retained->request = old.plan->request;
  result.plan = retained->plan;
  ReplanToProto(result, *retained, response);
  // Stored before the robot receives it (the caller answers after this
  // returns): the plan a robot holds survives its replica.
  if (old.has_origin) archive_->PersistNow(old.origin, response->plan());
  // A robot of a fleet mission drives the new plan now: the mission follows
  // (a Drive session's replan only once the session adopts it).
  if (missions_ != nullptr && mission_follows) {
    missions_->ReplacePlan(old.plan->plan_id, retained->plan_id);
  }
  archive_->Put(retained);
  archive_->PublishRetainedCount();
  metrics_->RecordReplan(result.stats.method, result.stats.total_ms * 1e-3,
                         static_cast<int>(result.stats.greedy_detours.size()));
  archive_->PublishEstimator();
  if (result.stats.replanned_encounter >= 0) archive_->SaveEstimator();
}

absl::StatusOr<DriveHost::AdoptedPlan> ReplanWork::AdoptPlan(const v1::DriveRequest& first,
                                                             const StopToken& stop,
                                                             const std::string& tenant_tag) {
  const StopToken bounded = stop.WithEarlierDeadline(absl::Now() + options_.max_request_time);
  ResolvedPlan resolved;
  RETURN_IF_ERROR(
      ResolvePlan(tenant_tag, first.plan_id(),
                  first.plan_ref_case() == v1::DriveRequest::kPlan ? &first.plan() : nullptr,
                  bounded, &resolved));
  DriveHost::AdoptedPlan out;
  out.grid = resolved.plan->plan.grid;
  out.map_id = resolved.plan->map_id;
  if (first.plan_ref_case() == v1::DriveRequest::kPlanId) {
    out.plan_id = first.plan_id();
    return out;
  }
  // An inline plan: retained under a new id so the session's replans name it.
  auto retained = std::make_shared<RetainedPlan>(*resolved.plan);
  retained->plan_id = NewPlanId(tenant_tag);
  out.plan_id = retained->plan_id;
  if (resolved.has_origin) {
    v1::PlanResponse proto;
    RetainedPlanToProto(*retained, &proto);
    archive_->Persist(resolved.origin, proto);
  }
  archive_->Put(retained);
  return out;
}

}  // namespace covplan
