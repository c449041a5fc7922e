// An LRU cache of immutable per-map objects with a memory budget in bytes and
// single flight: concurrent requests for the same missing key build it once,
// the others wait for that result (each until its own StopToken fires).
//
// ArtifactLru is the server's implementation of the engine's ArtifactCache
// (planner/engine/artifact_cache.h): every per-map artifact (grid, coverage
// area, partition, transitions) under its typed key, within one budget.
//
//   ArtifactLru cache(256 << 20, &metrics);
//   PlanningEngine engine(&registry, &cache, limits);
//   cache.EraseWithPrefix(map_id + "/");   // DeleteMap: drops and fences
//
// Failed builds are not cached. EraseWithPrefix also fences the prefix: a
// build that was already running when the erase happened returns its value
// to its own caller but does not store it, so a deleted map's artifacts
// cannot come back from a build that raced the delete. If the builder was stopped by its own
// request's deadline, a waiter whose token is still live retries the build.
// An object larger than the whole budget is returned but not kept.
//
// Thread-safety: all methods are thread-safe; values are shared immutable
// objects.
#ifndef COVPLAN_SERVER_ARTIFACT_LRU_H_
#define COVPLAN_SERVER_ARTIFACT_LRU_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <string>
#include <unordered_map>

#include <vector>
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "planner/engine/artifact_cache.h"

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
          flight->epoch = erase_epoch_;
          flights_.emplace(key, flight);
          leader = true;
          ++stats_.misses;
          Notify(&CacheObserver::OnCacheMiss);
        }
      }
      if (leader) {
        absl::StatusOr<Value> result = build(stop);
        std::vector<Value> dropped;  // freed after the lock is released
        absl::MutexLock lock(&mu_);
        flight->result = result;
        flight->done = true;
        flights_.erase(key);
        if (result.ok() && *result != nullptr && !Fenced(key, flight->epoch))
          Insert(key, *result, &dropped);
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
      const bool leader_stopped =
          absl::IsDeadlineExceeded(shared.status()) || absl::IsCancelled(shared.status());
      if (!leader_stopped || stop.ShouldStop()) return shared.status();
      // The leader gave up on its own deadline; try again (maybe as leader).
    }
    return absl::UnavailableError("artifact build kept being abandoned; retry");
  }

  // The cached value of `key` (now most recently used), or null. Not counted
  // as a hit or miss: those count builds avoided and done.
  Value Find(const std::string& key) {
    absl::MutexLock lock(&mu_);
    auto it = entries_.find(key);
    if (it == entries_.end()) return nullptr;
    lru_.splice(lru_.begin(), lru_, it->second.position);
    return it->second.value;
  }

  // Stores `value` under `key`, replacing an older value (its bytes are
  // released first), and evicts from the LRU end to stay within the budget.
  void Put(const std::string& key, Value value) {
    if (value == nullptr) return;
    std::vector<Value> dropped;  // freed after the lock is released
    absl::MutexLock lock(&mu_);
    Insert(key, value, &dropped);
  }

  // Drops every entry whose key starts with `prefix` (e.g. a deleted map).
  void EraseWithPrefix(const std::string& prefix) {
    std::vector<Value> dropped;  // freed after the lock is released
    absl::MutexLock lock(&mu_);
    ++erase_epoch_;
    erases_.push_back({prefix, erase_epoch_});
    if (erases_.size() > kMaxFences) erases_.erase(erases_.begin());
    for (auto it = entries_.begin(); it != entries_.end();) {
      if (it->first.compare(0, prefix.size(), prefix) == 0) {
        stats_.bytes -= it->second.bytes;
        dropped.push_back(std::move(it->second.value));
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
    uint64_t epoch = 0;  // erase_epoch_ when the build started
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
        return stop.cancelled()
                   ? absl::CancelledError("request cancelled")
                   : absl::DeadlineExceededError(
                         "deadline reached while waiting for a per-map artifact (grid, partition "
                         "or transitions) that another call is building");
      }
      absl::Duration wait = absl::Milliseconds(20);
      if (stop.has_deadline())
        wait = std::max(absl::ZeroDuration(), std::min(wait, stop.remaining()));
      mu_.AwaitWithTimeout(absl::Condition(&flight.done), wait);
    }
    return flight.result;
  }

  // Values it drops go to `*dropped`, for the caller to free once mu_ is
  // released: freeing a large artifact takes milliseconds, and gRPC threads
  // take mu_ to answer repeated hits.
  void Insert(const std::string& key, const Value& value, std::vector<Value>* dropped)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    const size_t bytes = size_fn_(*value);
    if (auto old = entries_.find(key); old != entries_.end()) {  // a replacement (Put)
      stats_.bytes -= old->second.bytes;
      dropped->push_back(std::move(old->second.value));
      lru_.erase(old->second.position);
      entries_.erase(old);
    }
    if (bytes > budget_bytes_) {  // would evict everything and still not fit
      stats_.entries = entries_.size();
      if (observer_ != nullptr) observer_->OnCacheSize(stats_.bytes, stats_.entries);
      return;
    }
    lru_.push_front(key);
    entries_[key] = Entry{value, bytes, lru_.begin()};
    stats_.bytes += bytes;
    while (stats_.bytes > budget_bytes_ && !lru_.empty()) {
      const std::string victim = lru_.back();
      auto it = entries_.find(victim);
      stats_.bytes -= it->second.bytes;
      dropped->push_back(std::move(it->second.value));
      entries_.erase(it);
      lru_.pop_back();
      ++stats_.evictions;
      Notify(&CacheObserver::OnCacheEviction);
    }
    stats_.entries = entries_.size();
    if (observer_ != nullptr) observer_->OnCacheSize(stats_.bytes, stats_.entries);
  }

  // True when an erase of a prefix of `key` happened after `epoch` (or so
  // long ago that it was forgotten: then refuse, to be safe).
  bool Fenced(const std::string& key, uint64_t epoch) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    if (epoch == erase_epoch_) return false;
    if (erases_.empty() || erases_.front().epoch > epoch + 1) return true;
    for (const Erase& e : erases_) {
      if (e.epoch > epoch && key.compare(0, e.prefix.size(), e.prefix) == 0) return true;
    }
    return false;
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
  struct Erase {
    std::string prefix;
    uint64_t epoch;
  };
  static constexpr size_t kMaxFences = 256;
  uint64_t erase_epoch_ ABSL_GUARDED_BY(mu_) = 0;
  std::vector<Erase> erases_ ABSL_GUARDED_BY(mu_);
};

// The server's ArtifactCache: one byte budget over all artifacts.
// Thread-safety: thread-safe.
class ArtifactLru final : public ArtifactCache {
 public:
  explicit ArtifactLru(size_t budget_bytes, CacheObserver* observer = nullptr)
      : lru_(
            budget_bytes, [](const Artifact& a) { return a.MemoryBytes(); }, observer) {}

  absl::StatusOr<Value> GetOrBuild(const std::string& key, const StopToken& stop,
                                   const Builder& build, bool* hit) override {
    return lru_.GetOrBuild(key, stop, build, hit);
  }
  Value Find(const std::string& key) override { return lru_.Find(key); }
  void Put(const std::string& key, Value value) override { lru_.Put(key, std::move(value)); }
  void EraseWithPrefix(const std::string& prefix) { lru_.EraseWithPrefix(prefix); }
  SharedLruCache<Artifact>::Stats stats() const { return lru_.stats(); }
  size_t budget_bytes() const { return lru_.budget_bytes(); }

 private:
  SharedLruCache<Artifact> lru_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_ARTIFACT_LRU_H_
