#include "server/worker_pool.h"

#include <algorithm>
#include <utility>

namespace covplan {

WorkerPool::WorkerPool(int threads, int max_queue) : max_queue_(std::max(0, max_queue)) {
  threads = std::max(1, threads);
  threads_.reserve(threads);
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Loop(); });
}

WorkerPool::~WorkerPool() { Shutdown(); }

bool WorkerPool::TrySubmit(std::function<void()> task) {
  return TrySubmit(std::move(task), /*group=*/"", /*max_running=*/0);
}

bool WorkerPool::TrySubmit(std::function<void()> task, const std::string& group, int max_running) {
  absl::MutexLock lock(&mu_);
  if (stopping_) return false;
  // Running plus waiting tasks may not exceed threads + max_queue.
  const size_t capacity = threads_.size() + static_cast<size_t>(max_queue_);
  if (static_cast<size_t>(active_ + queued_) >= capacity) return false;
  Group& g = groups_[group];
  g.max_running = std::max(0, max_running);
  if (g.queue.empty()) turns_.push_back(group);
  g.queue.push_back(std::move(task));
  ++queued_;
  return true;
}

std::map<std::string, WorkerPool::Group>::iterator WorkerPool::Runnable() {
  for (const std::string& name : turns_) {
    const auto it = groups_.find(name);
    if (it->second.max_running == 0 || it->second.running < it->second.max_running) return it;
  }
  return groups_.end();
}

void WorkerPool::Loop() {
  for (;;) {
    std::function<void()> task;
    std::string group;
    {
      absl::MutexLock lock(&mu_);
      mu_.Await(absl::Condition(
          +[](WorkerPool* p) ABSL_EXCLUSIVE_LOCKS_REQUIRED(p->mu_) { return p->CanTake(); }, this));
      const auto it = Runnable();
      if (it == groups_.end()) return;  // stopping and drained
      group = it->first;
      Group& g = it->second;
      task = std::move(g.queue.front());
      g.queue.pop_front();
      ++g.running;
      --queued_;
      ++active_;
      // Its turn is over: to the back of the line if it has more.
      turns_.erase(std::find(turns_.begin(), turns_.end(), group));
      if (!g.queue.empty()) turns_.push_back(group);
    }
    task();
    absl::MutexLock lock(&mu_);
    --active_;
    const auto it = groups_.find(group);
    if (--it->second.running == 0 && it->second.queue.empty()) groups_.erase(it);
  }
}

void WorkerPool::Shutdown() {
  absl::MutexLock join_lock(&join_mu_);
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

int WorkerPool::queued() const {
  absl::MutexLock lock(&mu_);
  return queued_;
}

int WorkerPool::active() const {
  absl::MutexLock lock(&mu_);
  return active_;
}

}  // namespace covplan
