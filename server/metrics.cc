#include "server/metrics.h"

namespace covplan {
namespace {

prometheus::Histogram::BucketBoundaries LatencyBuckets() {
  return {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.15, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60};
}

prometheus::Gauge* NewGauge(prometheus::Registry& registry, const std::string& name,
                            const std::string& help) {
  return &prometheus::BuildGauge().Name(name).Help(help).Register(registry).Add({});
}

prometheus::Counter* NewCounter(prometheus::Registry& registry, const std::string& name,
                                const std::string& help) {
  return &prometheus::BuildCounter().Name(name).Help(help).Register(registry).Add({});
}

}  // namespace

ServerMetrics::ServerMetrics() : registry_(std::make_shared<prometheus::Registry>()) {
  prometheus::Registry& r = *registry_;
  requests_ = &prometheus::BuildCounter()
                   .Name("covplan_requests_total")
                   .Help("gRPC requests handled, by method and status code")
                   .Register(r);
  request_duration_ = &prometheus::BuildHistogram()
                           .Name("covplan_request_duration_seconds")
                           .Help("gRPC request latency from arrival to reply, by method")
                           .Register(r);
  solve_duration_ = &prometheus::BuildHistogram()
                         .Name("covplan_plan_solve_duration_seconds")
                         .Help("Time a worker spent on one Plan request")
                         .Register(r)
                         .Add({}, LatencyBuckets());
  cut_short_ = NewCounter(r, "covplan_plans_cut_short_total",
                          "Plans whose tour search was stopped by the deadline or budget");
  queue_depth_ = NewGauge(r, "covplan_worker_queue_depth", "Requests waiting for a worker");
  in_flight_ = NewGauge(r, "covplan_solves_in_flight", "Requests being worked on now");
  worker_threads_ = NewGauge(r, "covplan_worker_threads", "Size of the worker pool");
  queue_capacity_ = NewGauge(r, "covplan_worker_queue_capacity", "Bound of the worker queue");
  cache_hits_ = NewCounter(r, "covplan_artifact_cache_hits_total",
                           "Per-map artifact lookups (grid, area, partition, transitions) served "
                           "from the cache or a concurrent build");
  cache_misses_ = NewCounter(r, "covplan_artifact_cache_misses_total",
                             "Per-map artifact lookups that had to build");
  cache_evictions_ = NewCounter(r, "covplan_artifact_cache_evictions_total",
                                "Artifacts evicted to stay within the byte budget");
  cache_bytes_ = NewGauge(r, "covplan_artifact_cache_bytes", "Bytes held by the cache");
  cache_entries_ = NewGauge(r, "covplan_artifact_cache_entries", "Entries in the cache");
  cache_budget_bytes_ =
      NewGauge(r, "covplan_artifact_cache_budget_bytes", "Memory budget of the cache");
  maps_stored_ = NewGauge(r, "covplan_maps_stored", "Maps in the registry");
  plans_retained_ = NewGauge(r, "covplan_plans_retained", "Plans addressable by plan_id");
  store_writable_ =
      NewGauge(r, "covplan_store_writable",
               "1 while the map store accepts writes, 0 when it is full or read-only");
  store_writable_->Set(1);
  replans_ = &prometheus::BuildCounter()
                  .Name("covplan_replans_total")
                  .Help("Replans answered, by the method that produced the plan")
                  .Register(r);
  plan_sources_ =
      &prometheus::BuildCounter()
           .Name("covplan_plan_source_total")
           .Help(
               "Plans answered, by source: cold search, remembered plan (cache_hit), "
               "search on from it (improved), search from a remembered tour (warm_start)")
           .Register(r);
  for (const char* s : {"cold", "cache_hit", "improved", "warm_start"})
    plan_sources_->Add({{"source", s}});
  hits_without_worker_ =
      NewCounter(r, "covplan_plan_hits_without_worker_total",
                 "Repeated cache hits answered on the network thread, without a worker "
                 "(also counted as cache_hit in covplan_plan_source_total)");
  replan_duration_ = &prometheus::BuildHistogram()
                          .Name("covplan_replan_duration_seconds")
                          .Help("Compute time of one replan")
                          .Register(r)
                          .Add({}, LatencyBuckets());
  greedy_detours_ = NewCounter(r, "covplan_replan_greedy_detours_total",
                               "Encounters handled by greedy detour (too little time to replan)");
  estimator_ =
      &prometheus::BuildGauge()
           .Name("covplan_replan_estimator")
           .Help("Replan runtime model f(m) = a + b m + c m^3 (seconds) and its sample count")
           .Register(r);
  drive_sessions_ = NewGauge(r, "covplan_drive_sessions", "Open Drive streaming sessions");
  drive_superseded_ = NewCounter(r, "covplan_drive_superseded_total",
                                 "Session replans dropped because a newer observation arrived");
}

void ServerMetrics::RecordReplan(const std::string& method, double seconds, int greedy_detours) {
  replans_->Add({{"method", method}}).Increment();
  replan_duration_->Observe(seconds);
  greedy_detours_->Increment(greedy_detours);
}

void ServerMetrics::SetReplanEstimator(double a, double b, double c, int64_t samples) {
  estimator_->Add({{"term", "a"}}).Set(a);
  estimator_->Add({{"term", "b"}}).Set(b);
  estimator_->Add({{"term", "c"}}).Set(c);
  estimator_->Add({{"term", "samples"}}).Set(static_cast<double>(samples));
}

void ServerMetrics::RecordRequest(const std::string& method, const std::string& code,
                                  double seconds, const std::string& tenant) {
  if (tenant.empty()) {
    requests_->Add({{"method", method}, {"code", code}}).Increment();
    request_duration_->Add({{"method", method}}, LatencyBuckets()).Observe(seconds);
    return;
  }
  requests_->Add({{"method", method}, {"code", code}, {"tenant", tenant}}).Increment();
  request_duration_->Add({{"method", method}, {"tenant", tenant}}, LatencyBuckets())
      .Observe(seconds);
}

void ServerMetrics::RecordSolve(double seconds, bool cut_short) {
  solve_duration_->Observe(seconds);
  if (cut_short) cut_short_->Increment();
}

void ServerMetrics::RecordPlanSource(const std::string& source) {
  plan_sources_->Add({{"source", source}}).Increment();
}

void ServerMetrics::OnCacheSize(size_t bytes, size_t entries) {
  cache_bytes_->Set(static_cast<double>(bytes));
  cache_entries_->Set(static_cast<double>(entries));
}

}  // namespace covplan
