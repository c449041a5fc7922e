// What a planning call works with, shared by Plan and PlanFleet: the time
// budget its gRPC deadline leaves, the map its PlanRequest names (stored or
// inline), and the status of work that its deadline or cancellation stopped
// before a first plan.
//
//   ASSIGN_OR_RETURN(CallBudget budget,
//                    BudgetFor(options, call, request.time_limit_s(), cancel, absl::Now()));
//   ASSIGN_OR_RETURN(MapSource source, PlanMapSource(store, options.limits, call, request));
//   ... engine.Plan(source, r) with r.common.time_limit_s = budget.time_limit_s,
//       r.common.stop = budget.stop ...
//   if (IsStop(status)) return StoppedStatus(status, cancel, call, start, max_request_time);
//
// Thread-safety: stateless functions (the store is thread-safe).
#ifndef COVPLAN_SERVER_SOLVE_INPUTS_H_
#define COVPLAN_SERVER_SOLVE_INPUTS_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/common/stop_token.h"
#include "planner/engine/engine.h"
#include "server/call_info.h"
#include "server/map_repository.h"
#include "server/service_options.h"

namespace covplan {

struct CallBudget {
  double time_limit_s = 0.0;
  StopToken stop;  // the call's cancel token with the budget's deadline
};

// The budget of work starting at `start`: `requested_s` (0: the server's
// default_budget_s), never past the call's deadline minus the reply margin;
// without a deadline, stopped after max_request_time. RESOURCE_EXHAUSTED
// when the deadline had room on arrival but the queue used it up,
// DEADLINE_EXCEEDED when it never had.
absl::StatusOr<CallBudget> BudgetFor(const ServiceOptions& options, const CallInfo& call,
                                     double requested_s, const StopToken& cancel, absl::Time start);

// Where a call's map comes from: a stored map the tenant owns (NOT_FOUND
// otherwise, also for a deleted or damaged one), or the inline one.
absl::StatusOr<MapSource> PlanMapSource(MapRepository* store, const EngineLimits& limits,
                                        const CallInfo& call, const v1::PlanRequest& request);

// Whether the engine stopped on a deadline or a cancellation.
bool IsStop(const absl::Status& status);

// The status for work that stopped before a first plan (`started`: when it
// left the queue): the client's cancellation wins; then overload (most of
// the deadline spent in the queue: RESOURCE_EXHAUSTED); then the deadline,
// or the server's limit for calls without one.
absl::Status StoppedStatus(const absl::Status& status, const StopToken& cancel,
                           const CallInfo& call, absl::Time started,
                           absl::Duration max_request_time);

}  // namespace covplan

#endif  // COVPLAN_SERVER_SOLVE_INPUTS_H_
