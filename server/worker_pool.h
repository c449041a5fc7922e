// A fixed pool of worker threads with a bounded queue: the server's solves
// run here, never on gRPC threads. When the queue is full TrySubmit refuses
// at once, so the caller can answer RESOURCE_EXHAUSTED instead of letting
// requests pile up.
//
//   WorkerPool pool(/*threads=*/2, /*max_queue=*/8);
//   if (!pool.TrySubmit([] { Solve(); })) Reject();
//   pool.Shutdown();  // runs what is queued, then joins
//
// Tasks may belong to a group (the server's tenants): groups take turns, a
// free worker taking the oldest task of the next group in turn, and a
// group may be bounded in how many of its tasks run at once; its other
// tasks wait while other groups' tasks run. With one group the pool is FIFO.
//
//   pool.TrySubmit([] { Solve(); }, /*group=*/"fleet-a", /*max_running=*/1);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_WORKER_POOL_H_
#define COVPLAN_SERVER_WORKER_POOL_H_

#include <deque>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"

namespace covplan {

class WorkerPool {
 public:
  WorkerPool(int threads, int max_queue);
  ~WorkerPool();  // Shutdown()
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // False when the queue already holds max_queue tasks or the pool is shut
  // down; the task is then not run.
  bool TrySubmit(std::function<void()> task);
  // The same, in `group`, of which at most `max_running` tasks run at once
  // (0: no bound; the newest submission's bound holds for the group).
  bool TrySubmit(std::function<void()> task, const std::string& group, int max_running);

  // Stops accepting, runs the queued tasks, joins the threads. Idempotent.
  void Shutdown();

  int queued() const;  // waiting, not yet started
  int active() const;  // running now
  int threads() const { return static_cast<int>(threads_.size()); }
  int max_queue() const { return max_queue_; }

 private:
  struct Group {
    std::deque<std::function<void()>> queue;
    int running = 0;
    int max_running = 0;
  };
  void Loop();
  // The next group in turn with a task it may start (groups_.end() when
  // none).
  std::map<std::string, Group>::iterator Runnable() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  bool CanTake() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    return (stopping_ && queued_ == 0) || Runnable() != groups_.end();
  }

  const int max_queue_;
  mutable absl::Mutex mu_;
  std::map<std::string, Group> groups_ ABSL_GUARDED_BY(mu_);
  // The groups with waiting tasks, in turn order.
  std::deque<std::string> turns_ ABSL_GUARDED_BY(mu_);
  int queued_ ABSL_GUARDED_BY(mu_) = 0;
  int active_ ABSL_GUARDED_BY(mu_) = 0;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::vector<std::thread> threads_;
  absl::Mutex join_mu_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_WORKER_POOL_H_
