// The knobs of the CoveragePlanner service (covplan-server's flags map onto
// them): input limits, the solve pool and its queue, the artifact cache,
// budgets and deadlines, retained and stored plans, Drive sessions. Every
// part of the service reads its own fields from one validated struct.
//
//   ServiceOptions options;
//   options.worker_threads = 4;
//   RETURN_IF_ERROR(options.Validate());
//
// Thread-safety: a plain value; read-only once the service is built.
#ifndef COVPLAN_SERVER_SERVICE_OPTIONS_H_
#define COVPLAN_SERVER_SERVICE_OPTIONS_H_

#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "planner/engine/limits.h"
#include "planner/engine/planner.h"
#include "server/tenant_quotas.h"

namespace covplan {

struct ServiceOptions {
  // Input and engine limits; limits.plan_memory remembers plans in the
  // artifact cache (planner/engine/plan_memory.h): identical requests
  // answered at once, new start poses warm-started.
  EngineLimits limits;
  int worker_threads = 2;
  int max_queue = 16;                        // waiting requests beyond the workers
  size_t cache_budget_bytes = 256ull << 20;  // per-map artifact cache
  // Tour search budget without a deadline.
  double default_budget_s = CommonOptions::kDefaultTimeLimitS;
  // Without a deadline, the whole call (artifacts included) stops after
  // this long with DEADLINE_EXCEEDED rather than holding a worker forever.
  absl::Duration max_request_time = absl::Seconds(120);
  absl::Duration deadline_margin = absl::Milliseconds(25);  // kept for the reply
  absl::Duration plan_ttl = absl::Minutes(10);
  size_t max_retained_plans = 256;
  // Plans on stored maps are also written to the store (plans/), so a robot
  // resumes its mission with its plan_id after a restart; the newest this
  // many are kept.
  int64_t max_stored_plans = 4096;
  // Drive streaming sessions: how many may be open, and how long one may go
  // without a message before it is ended.
  int max_sessions = 64;
  absl::Duration session_idle = absl::Seconds(120);
  // Live event streams (GET /v1/events on the JSON API) open at once; each
  // holds one of the HTTP server's threads.
  int max_live_streams = 4;
  // This replica's name among replicas that share one store ([a-z0-9_],
  // at most 32; "" for a server alone): what it learns (the replan
  // estimator) is kept under its own name, so no replica overwrites
  // another's.
  std::string replica;
  // Every tenant's quotas unless the quota file (server/tenant_quotas.h)
  // overrides them; without a token file all callers are one tenant.
  TenantQuota tenant_quota;

  absl::Status Validate() const;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_SERVICE_OPTIONS_H_
