#include "server/solve_inputs.h"

#include <algorithm>
#include <memory>
#include <string>

#include "absl/strings/str_format.h"
#include "api/convert.h"
#include "planner/common/status_macros.h"
#include "server/map_sources.h"
#include "server/not_found.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

// Work stopped by its deadline before a first plan is overload
// (RESOURCE_EXHAUSTED), not a too-short deadline, when it spent more than this
// share of its deadline in the queue.
constexpr double kQueueShareForOverload = 0.1;

}  // namespace

absl::StatusOr<CallBudget> BudgetFor(const ServiceOptions& options, const CallInfo& call,
                                     double requested_s, const StopToken& cancel,
                                     absl::Time start) {
  // The budget: the request's time limit (or the server default), and never
  // past the call's deadline minus the margin kept for sending the reply.
  double budget_s = requested_s > 0 ? requested_s : options.default_budget_s;
  StopToken stop = cancel;
  if (call.deadline != absl::InfiniteFuture()) {
    const absl::Time reply_by = call.deadline - options.deadline_margin;
    if (reply_by <= start && call.start + options.deadline_margin < call.deadline) {
      // The budget was there on arrival and went into the queue: overload.
      return absl::ResourceExhaustedError(absl::StrFormat(
          "server busy: the call waited %d ms for a worker and has no time left to plan",
          absl::ToInt64Milliseconds(start - call.start)));
    }
    if (reply_by <= start) {
      return absl::DeadlineExceededError(
          absl::StrFormat("deadline of %d ms leaves no time to plan",
                          absl::ToInt64Milliseconds(call.deadline - call.start)));
    }
    stop = cancel.WithEarlierDeadline(reply_by);
    budget_s = std::min(budget_s, absl::ToDoubleSeconds(reply_by - start));
  } else {
    stop = cancel.WithEarlierDeadline(start + options.max_request_time);
  }
  return CallBudget{std::max(budget_s, 1e-3), stop};
}

absl::StatusOr<MapSource> PlanMapSource(MapRepository* store, const EngineLimits& limits,
                                        const CallInfo& call, const v1::PlanRequest& request) {
  std::string map_id;
  std::shared_ptr<const v1::Map> inline_map;
  switch (request.map_ref_case()) {
    case v1::PlanRequest::kMapId:
      RETURN_IF_ERROR(ValidateMapId(request.map_id()));
      map_id = request.map_id();
      if (!OwnsMap(call.tenant_tag, map_id)) return MapNotFound(map_id);
      // A deleted map, or one found damaged, is not planned from the cache.
      if (absl::Status s = store->Check(map_id); !s.ok()) {
        return absl::IsNotFound(s) ? MapNotFound(map_id) : s;
      }
      break;
    case v1::PlanRequest::kMap:
      map_id = ComputeMapId(request.map());
      inline_map = std::make_shared<const v1::Map>(request.map());
      break;
    default:
      return absl::InvalidArgumentError("PlanRequest needs map_id or an inline map");
  }
  return MapSourceFor(store, limits, map_id, inline_map);
}

bool IsStop(const absl::Status& status) {
  return absl::IsDeadlineExceeded(status) || absl::IsCancelled(status);
}

absl::Status StoppedStatus(const absl::Status& status, const StopToken& cancel,
                           const CallInfo& call, absl::Time started,
                           absl::Duration max_request_time) {
  if (cancel.cancelled())
    return absl::CancelledError("call cancelled (by the client, or by the server's drain)");
  // A call that spent a real share of its deadline waiting for a worker was
  // refused by overload, not by its own deadline: say so with the code a
  // client retries on (elsewhere).
  if (call.deadline != absl::InfiniteFuture() && absl::IsDeadlineExceeded(status)) {
    const absl::Duration waited = started - call.start;
    if (waited > kQueueShareForOverload * (call.deadline - call.start)) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "server busy: the call waited %d ms of its %d ms deadline for a worker and had no time "
          "left for a first plan; retry later or elsewhere",
          absl::ToInt64Milliseconds(waited),
          absl::ToInt64Milliseconds(call.deadline - call.start)));
    }
  }
  if (call.deadline == absl::InfiniteFuture() && absl::IsDeadlineExceeded(status)) {
    return absl::DeadlineExceededError(
        absl::StrFormat("no plan within the server's limit of %g s per call without a deadline "
                        "(--max_request_s) (%s); use a wider tool or a smaller map",
                        absl::ToDoubleSeconds(max_request_time), status.message()));
  }
  if (absl::IsDeadlineExceeded(status) || call.deadline != absl::InfiniteFuture()) {
    return absl::DeadlineExceededError(
        absl::StrFormat("deadline of %d ms too short for a first plan (%s)",
                        absl::ToInt64Milliseconds(call.deadline - call.start), status.message()));
  }
  return status;
}

}  // namespace covplan
