#include "server/service.h"

#include "planner/assembly/builtin_planners.h"

namespace covplan {

CoveragePlannerService::CoveragePlannerService(const ServiceOptions& options, MapRepository* store,
                                               ServerMetrics* metrics, const TenantTokens* tokens,
                                               const TenantQuotas* quotas)
    : options_(options),
      cache_(options.cache_budget_bytes, metrics),
      registry_(BuiltinPlanners()),
      engine_(&registry_, &cache_, options.limits),
      own_quotas_(quotas == nullptr ? *TenantQuotas::Load(options.tenant_quota, /*path=*/"")
                                    : nullptr),
      quotas_(quotas == nullptr ? own_quotas_.get() : quotas),
      gate_(metrics, tokens),
      admission_(options_, metrics, &pool_, quotas_),
      archive_(options_, store, metrics, &engine_, &io_pool_),
      progress_(store, &io_pool_, 4 * options.max_retained_plans + 64),
      live_(options.max_live_streams, /*queue_limit=*/1024),
      missions_(4 * options.max_retained_plans + 16, store),
      replan_work_(options_, store, metrics, &engine_, &archive_, &progress_, &admission_,
                   &missions_),
      maps_(options_, store, &cache_, metrics, &gate_, &admission_, quotas_, &io_pool_,
            &read_pool_),
      plans_(options_, store, metrics, &engine_, &gate_, &admission_, &served_, &archive_,
             &warm_pool_, background_stop_),
      fleets_(options_, store, metrics, &engine_, &gate_, &admission_, &archive_, &missions_),
      missions_rpc_(options_, store, metrics, &engine_, &gate_, &admission_, &archive_, &progress_,
                    &missions_, &drive_),
      replans_(&gate_, &admission_, &replan_work_),
      drive_(options_, metrics, &gate_, &admission_, &replan_work_, &progress_, &missions_, &live_),
      io_pool_(/*threads=*/2, /*max_queue=*/64),
      read_pool_(/*threads=*/1, /*max_queue=*/256),
      // Admission is bounded by SolveAdmission; the pool's own bound is slack
      // for solves that have released their slot but not yet returned.
      pool_(options.worker_threads, 2 * (options.worker_threads + options.max_queue)),
      warm_pool_(/*threads=*/1, /*max_queue=*/4) {
  metrics->worker_threads().Set(options.worker_threads);
  metrics->queue_capacity().Set(options.max_queue);
  metrics->cache_budget_bytes().Set(static_cast<double>(options.cache_budget_bytes));
  metrics->maps_stored().Set(static_cast<double>(store->size()));
}

CoveragePlannerService::~CoveragePlannerService() { Shutdown(); }

void CoveragePlannerService::StartDraining() {
  gate_.StartDraining();
  background_stop_.Cancel();
  drive_.EndAll();
}

void CoveragePlannerService::Shutdown() {
  background_stop_.Cancel();
  warm_pool_.Shutdown();
  pool_.Shutdown();
  // No solve runs any more: the repeated hits never used are stored now.
  archive_.StoreUnusedAliases();
  io_pool_.Shutdown();
  read_pool_.Shutdown();
}

}  // namespace covplan
