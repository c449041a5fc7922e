// A fixed pool of worker threads with a bounded queue: the server's solves
// run here, never on gRPC threads. When the queue is full TrySubmit refuses
// at once, so the caller can answer RESOURCE_EXHAUSTED instead of letting
// requests pile up.
//
//   WorkerPool pool(/*threads=*/2, /*max_queue=*/8);
//   if (!pool.TrySubmit([] { Solve(); })) Reject();
//   pool.Shutdown();  // runs what is queued, then joins
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_WORKER_POOL_H_
#define COVPLAN_SERVER_WORKER_POOL_H_

#include <deque>
#include <functional>
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

  // Stops accepting, runs the queued tasks, joins the threads. Idempotent.
  void Shutdown();

  int queued() const;  // waiting, not yet started
  int active() const;  // running now
  int threads() const { return static_cast<int>(threads_.size()); }
  int max_queue() const { return max_queue_; }

 private:
  void Loop();

  const int max_queue_;
  mutable absl::Mutex mu_;
  std::deque<std::function<void()>> queue_ ABSL_GUARDED_BY(mu_);
  int active_ ABSL_GUARDED_BY(mu_) = 0;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::vector<std::thread> threads_;
  absl::Mutex join_mu_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_WORKER_POOL_H_
