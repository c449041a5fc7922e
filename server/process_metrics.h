// Process metrics read at scrape time: resident memory, virtual memory and
// CPU seconds of this process, from /proc/self (Linux). prometheus-cpp has no
// process collector; the dashboard's memory panel and the cache budget
// reasoning in docs/deploy.md need the resident size.
//
//   auto process = std::make_shared<ProcessMetrics>();
//   exposer->RegisterCollectable(process);
//
// Exports covplan_process_resident_memory_bytes,
// covplan_process_virtual_memory_bytes and covplan_process_cpu_seconds_total.
// Where /proc cannot be read, the families are simply absent.
//
// Thread-safety: Collect() is const and reads only /proc; safe concurrently.
#ifndef COVPLAN_SERVER_PROCESS_METRICS_H_
#define COVPLAN_SERVER_PROCESS_METRICS_H_

#include <vector>

#include "prometheus/collectable.h"
#include "prometheus/metric_family.h"

namespace covplan {

class ProcessMetrics : public prometheus::Collectable {
 public:
  std::vector<prometheus::MetricFamily> Collect() const override;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PROCESS_METRICS_H_
