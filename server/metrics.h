// The server's Prometheus metrics (prometheus-cpp), conventional names and
// base units:
//   covplan_requests_total{method,code}               counter
//   covplan_request_duration_seconds{method}          histogram
//   covplan_plan_solve_duration_seconds               histogram
//   covplan_plans_cut_short_total                     counter
//   covplan_worker_queue_depth / covplan_solves_in_flight   gauges
//   covplan_worker_threads / covplan_worker_queue_capacity  gauges
//   covplan_artifact_cache_{hits,misses,evictions}_total  counters
//   covplan_artifact_cache_{bytes,entries,budget_bytes}   gauges
//   covplan_maps_stored / covplan_plans_retained       gauges
//   covplan_drive_sessions                             gauge
//   covplan_drive_superseded_total                     counter
//
//   ServerMetrics metrics;
//   exposer.RegisterCollectable(metrics.registry());
//   metrics.RecordRequest("Plan", "OK", 0.042);
//
// Thread-safety: all methods are thread-safe (prometheus-cpp metrics are).
#ifndef COVPLAN_SERVER_METRICS_H_
#define COVPLAN_SERVER_METRICS_H_

#include <memory>
#include <string>

#include "prometheus/counter.h"
#include "prometheus/family.h"
#include "prometheus/gauge.h"
#include "prometheus/histogram.h"
#include "prometheus/registry.h"
#include "server/artifact_lru.h"

namespace covplan {

class ServerMetrics : public CacheObserver {
 public:
  ServerMetrics();

  std::shared_ptr<prometheus::Registry> registry() const { return registry_; }

  // `code` is the gRPC status code name, e.g. "OK", "INVALID_ARGUMENT".
  // `tenant` (with --token_file: the caller's tenant, "unauthenticated"
  // for a call without a valid token; a set bounded by the token file)
  // labels the call's series; without one they carry no tenant label.
  void RecordRequest(const std::string& method, const std::string& code, double seconds,
                     const std::string& tenant = "");
  void RecordSolve(double seconds, bool cut_short);
  // `source` is PlanOriginName: "cold", "cache_hit", "improved", "warm_start".
  void RecordPlanSource(const std::string& source);
  void RecordReplan(const std::string& method, double seconds, int greedy_detours);
  void SetReplanEstimator(double a, double b, double c, int64_t samples);

  prometheus::Gauge& queue_depth() { return *queue_depth_; }
  prometheus::Gauge& in_flight() { return *in_flight_; }
  prometheus::Gauge& worker_threads() { return *worker_threads_; }
  prometheus::Gauge& queue_capacity() { return *queue_capacity_; }
  prometheus::Gauge& cache_budget_bytes() { return *cache_budget_bytes_; }
  prometheus::Gauge& maps_stored() { return *maps_stored_; }
  prometheus::Gauge& plans_retained() { return *plans_retained_; }
  prometheus::Gauge& drive_sessions() { return *drive_sessions_; }
  prometheus::Counter& drive_superseded() { return *drive_superseded_; }
  prometheus::Gauge& store_writable() { return *store_writable_; }
  prometheus::Counter& hits_without_worker() { return *hits_without_worker_; }

  // CacheObserver.
  void OnCacheHit() override { cache_hits_->Increment(); }
  void OnCacheMiss() override { cache_misses_->Increment(); }
  void OnCacheEviction() override { cache_evictions_->Increment(); }
  void OnCacheSize(size_t bytes, size_t entries) override;

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Family<prometheus::Counter>* requests_;
  prometheus::Family<prometheus::Histogram>* request_duration_;
  prometheus::Histogram* solve_duration_;
  prometheus::Counter* cut_short_;
  prometheus::Gauge* queue_depth_;
  prometheus::Gauge* in_flight_;
  prometheus::Gauge* worker_threads_;
  prometheus::Gauge* queue_capacity_;
  prometheus::Counter* cache_hits_;
  prometheus::Counter* cache_misses_;
  prometheus::Counter* cache_evictions_;
  prometheus::Gauge* cache_bytes_;
  prometheus::Gauge* cache_entries_;
  prometheus::Gauge* cache_budget_bytes_;
  prometheus::Gauge* maps_stored_;
  prometheus::Gauge* plans_retained_;
  prometheus::Gauge* store_writable_;
  prometheus::Family<prometheus::Counter>* replans_;
  prometheus::Family<prometheus::Counter>* plan_sources_;
  prometheus::Histogram* replan_duration_;
  prometheus::Counter* greedy_detours_;
  prometheus::Family<prometheus::Gauge>* estimator_;
  prometheus::Gauge* drive_sessions_;
  prometheus::Counter* drive_superseded_;
  prometheus::Counter* hits_without_worker_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_METRICS_H_
