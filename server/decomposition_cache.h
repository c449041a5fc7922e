// An LRU cache of immutable per-map objects with a memory budget in bytes and
// single flight: concurrent requests for the same missing key build it once,
// the others wait for that result (each until its own StopToken fires).
//
// The server caches Decompositions (grid + rank partition + transitions)
// keyed by map_id + DecompositionOptions::CacheKey():
//
//   DecompositionCache cache(256 << 20, &metrics);
//   bool hit = false;
//   absl::StatusOr<std::shared_ptr<const Decomposition>> d = cache.GetOrBuild(
//       key, stop, [&](const StopToken& s) { return BuildDecomposition(map, opt, s); }, &hit);
//
// Failed builds are not cached. If the builder was stopped by its own
// request's deadline, a waiter whose token is still live retries the build.
// An object larger than the whole budget is returned but not kept.
//
// Thread-safety: all methods are thread-safe; values are shared immutable
// objects.
#ifndef COVPLAN_SERVER_DECOMPOSITION_CACHE_H_
#define COVPLAN_SERVER_DECOMPOSITION_CACHE_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <string>
#include <unordered_map>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "planner/plan/coverage_planner.h"

namespace covplan {

// Receives cache events (e.g. to export metrics). Called with the cache's
// lock held: implementations must be quick, thread-safe and must not call
// back into the cache.
class CacheObserver {
 public:
  virtual ~CacheObserver() = default;
  virtual void OnCacheHit() = 0;
  virtual void OnCacheMiss() = 0;
  virtual void OnCacheEviction() = 0;
  virtual void OnCacheSize(size_t bytes, size_t entries) = 0;
};

template <typename T>
class SharedLruCache {
 public:
  using Value = std::shared_ptr<const T>;
  using Builder = std::function<absl::StatusOr<Value>(const StopToken&)>;
  using SizeFn = std::function<size_t(const T&)>;

  struct Stats {
    int64_t hits = 0;
    int64_t misses = 0;
    int64_t evictions = 0;
    size_t bytes = 0;
    size_t entries = 0;
  };

  SharedLruCache(size_t budget_bytes, SizeFn size_fn, CacheObserver* observer = nullptr)
      : budget_bytes_(budget_bytes), size_fn_(std::move(size_fn)), observer_(observer) {}

  // `*hit` is true when the value came from the cache or from another
  // request's concurrent build.
  absl::StatusOr<Value> GetOrBuild(const std::string& key, const StopToken& stop,
                                   const Builder& build, bool* hit) {
    *hit = false;
    for (int attempt = 0; attempt < 4; ++attempt) {
      std::shared_ptr<Flight> flight;
      bool leader = false;
      {
        absl::MutexLock lock(&mu_);
        if (auto it = entries_.find(key); it != entries_.end()) {
          lru_.splice(lru_.begin(), lru_, it->second.position);
          ++stats_.hits;
          Notify(&CacheObserver::OnCacheHit);
          *hit = true;
          return it->second.value;
        }
        if (auto it = flights_.find(key); it != flights_.end()) {
          flight = it->second;
        } else {
          flight = std::make_shared<Flight>();
          flights_.emplace(key, flight);
          leader = true;
          ++stats_.misses;
          Notify(&CacheObserver::OnCacheMiss);
        }
      }
      if (leader) {
        absl::StatusOr<Value> result = build(stop);
        absl::MutexLock lock(&mu_);
        flight->result = result;
        flight->done = true;
        flights_.erase(key);
        if (result.ok() && *result != nullptr) Insert(key, *result);
        return result;
      }
      absl::StatusOr<Value> shared = Wait(*flight, stop);
      if (shared.ok()) {
        absl::MutexLock lock(&mu_);
        ++stats_.hits;
        Notify(&CacheObserver::OnCacheHit);
        *hit = true;
        return shared;
      }
      const bool leader_stopped = absl::IsDeadlineExceeded(shared.status()) ||
                                  absl::IsCancelled(shared.status());
      if (!leader_stopped || stop.ShouldStop()) return shared.status();
      // The leader gave up on its own deadline; try again (maybe as leader).
    }
    return absl::UnavailableError("decomposition build kept being abandoned; retry");
  }

  // Drops every entry whose key starts with `prefix` (e.g. a deleted map).
  void EraseWithPrefix(const std::string& prefix) {
    absl::MutexLock lock(&mu_);
    for (auto it = entries_.begin(); it != entries_.end();) {
      if (it->first.compare(0, prefix.size(), prefix) == 0) {
        stats_.bytes -= it->second.bytes;
        lru_.erase(it->second.position);
        it = entries_.erase(it);
      } else {
        ++it;
      }
    }
    stats_.entries = entries_.size();
    if (observer_ != nullptr) observer_->OnCacheSize(stats_.bytes, stats_.entries);
  }

  Stats stats() const {
    absl::MutexLock lock(&mu_);
    return stats_;
  }
  size_t budget_bytes() const { return budget_bytes_; }

 private:
  struct Flight {
    bool done = false;
    absl::StatusOr<Value> result = absl::UnknownError("not built");
  };
  struct Entry {
    Value value;
    size_t bytes = 0;
    typename std::list<std::string>::iterator position;
  };

  absl::StatusOr<Value> Wait(Flight& flight, const StopToken& stop) {
    absl::MutexLock lock(&mu_);
    while (!flight.done) {
      if (stop.ShouldStop()) {
        return stop.cancelled() ? absl::CancelledError("request cancelled")
                                : absl::DeadlineExceededError(
                                      "deadline reached while waiting for the decomposition");
      }
      absl::Duration wait = absl::Milliseconds(20);
      if (stop.has_deadline()) wait = std::max(absl::ZeroDuration(), std::min(wait, stop.remaining()));
      mu_.AwaitWithTimeout(absl::Condition(&flight.done), wait);
    }
    return flight.result;
  }

  void Insert(const std::string& key, const Value& value) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    const size_t bytes = size_fn_(*value);
    if (bytes > budget_bytes_) return;  // would evict everything and still not fit
    lru_.push_front(key);
    entries_[key] = Entry{value, bytes, lru_.begin()};
    stats_.bytes += bytes;
    while (stats_.bytes > budget_bytes_ && !lru_.empty()) {
      const std::string victim = lru_.back();
      auto it = entries_.find(victim);
      stats_.bytes -= it->second.bytes;
      entries_.erase(it);
      lru_.pop_back();
      ++stats_.evictions;
      Notify(&CacheObserver::OnCacheEviction);
    }
    stats_.entries = entries_.size();
    if (observer_ != nullptr) observer_->OnCacheSize(stats_.bytes, stats_.entries);
  }

  void Notify(void (CacheObserver::*event)()) {
    if (observer_ != nullptr) (observer_->*event)();
  }

  const size_t budget_bytes_;
  const SizeFn size_fn_;
  CacheObserver* const observer_;
  mutable absl::Mutex mu_;
  std::list<std::string> lru_ ABSL_GUARDED_BY(mu_);  // front = most recently used
  std::unordered_map<std::string, Entry> entries_ ABSL_GUARDED_BY(mu_);
  std::unordered_map<std::string, std::shared_ptr<Flight>> flights_ ABSL_GUARDED_BY(mu_);
  Stats stats_ ABSL_GUARDED_BY(mu_);
};

class DecompositionCache : public SharedLruCache<Decomposition> {
 public:
  DecompositionCache(size_t budget_bytes, CacheObserver* observer = nullptr)
      : SharedLruCache(budget_bytes, [](const Decomposition& d) { return d.MemoryBytes(); },
                       observer) {}
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_DECOMPOSITION_CACHE_H_
