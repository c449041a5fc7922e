// The robot's latest progress on each plan, as Replan calls and Drive
// sessions report it: kept in memory (bounded, oldest report dropped) and
// written to the MapRepository off the caller's path, coalesced, so Resume
// continues from where the robot stopped, after a restart too.
//
//   ProgressLog progress(store, &io_pool, /*max_plans=*/1088);
//   progress.Record(plan_id, report);
//   std::optional<v1::RobotProgress> at = progress.Recorded(plan_id);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_PROGRESS_LOG_H_
#define COVPLAN_SERVER_PROGRESS_LOG_H_

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "covplan/v1/covplan.pb.h"
#include "server/map_repository.h"
#include "server/worker_pool.h"

namespace covplan {

class ProgressLog {
 public:
  // `store` and `io_pool` outlive this; at most `max_plans` reports are kept
  // in memory.
  ProgressLog(MapRepository* store, WorkerPool* io_pool, size_t max_plans)
      : store_(store), io_pool_(io_pool), max_plans_(max_plans) {}

  // Keeps `progress` as the latest on `plan_id` (ids over 64 bytes are not
  // kept) and queues its write.
  void Record(const std::string& plan_id, const v1::RobotProgress& progress);
  // The recorded progress, from memory or the store.
  std::optional<v1::RobotProgress> Recorded(const std::string& plan_id);

 private:
  void Flush();

  MapRepository* const store_;
  WorkerPool* const io_pool_;
  const size_t max_plans_;
  // Latest progress per plan (bounded), and those not yet written.
  absl::Mutex mu_;
  std::map<std::string, std::pair<uint64_t, v1::RobotProgress>> progress_ ABSL_GUARDED_BY(mu_);
  std::set<std::string> dirty_ ABSL_GUARDED_BY(mu_);
  bool flush_queued_ ABSL_GUARDED_BY(mu_) = false;
  uint64_t clock_ ABSL_GUARDED_BY(mu_) = 0;
  // Held by Flush from its snapshot to its last write, so that two flushes
  // on the I/O pool's threads write in the order they took their snapshots
  // (else an older report could land after a newer one).
  absl::Mutex write_mu_ ABSL_ACQUIRED_BEFORE(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PROGRESS_LOG_H_
