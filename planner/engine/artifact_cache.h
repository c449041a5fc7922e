// Per-map artifacts (grid, coverage area, rank partition, transitions, ...)
// are built once, immutable, and shared through an ArtifactCache. The engine
// declares the interface; the host picks the implementation: covplan-server
// supplies a bounded, single-flight LRU (server/artifact_lru.h), the CLI the
// small LocalArtifactCache below.
//
// Keys are typed: an ArtifactKey<T> can only fetch a T. A derived artifact's
// key extends its parent's (`grid.Derive<CoverageArea>("area", params)`), so
// every artifact of a map starts with "<map_id>/" and one prefix erase drops
// them all.
//
//   ArtifactKey<GridArtifact> key = ArtifactKey<GridArtifact>::Root(map_id, "grid", "cell=0.8");
//   bool hit = false;
//   ASSIGN_OR_RETURN(std::shared_ptr<const GridArtifact> g,
//                    GetOrBuild(cache, key, stop, [&](const StopToken& s) { return Build(s); },
//                    &hit));
//
// Thread-safety: implementations must be thread-safe (say so in their
// comments); artifacts are immutable.
#ifndef COVPLAN_PLANNER_ENGINE_ARTIFACT_CACHE_H_
#define COVPLAN_PLANNER_ENGINE_ARTIFACT_CACHE_H_

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "planner/common/stop_token.h"

namespace covplan {

// Base of everything the cache holds.
class Artifact {
 public:
  virtual ~Artifact() = default;
  virtual size_t MemoryBytes() const = 0;
};

template <typename T>
class ArtifactKey {
 public:
  static ArtifactKey Root(const std::string& map_id, const std::string& kind,
                          const std::string& params) {
    return ArtifactKey(absl::StrCat(map_id, "/", kind, "(", params, ")"));
  }
  template <typename U>
  ArtifactKey<U> Derive(const std::string& kind, const std::string& params) const {
    return ArtifactKey<U>::FromText(absl::StrCat(text_, "|", kind, "(", params, ")"));
  }
  static ArtifactKey FromText(std::string text) { return ArtifactKey(std::move(text)); }
  const std::string& text() const { return text_; }

 private:
  explicit ArtifactKey(std::string text) : text_(std::move(text)) {}
  std::string text_;
};

class ArtifactCache {
 public:
  using Value = std::shared_ptr<const Artifact>;
  using Builder = std::function<absl::StatusOr<Value>(const StopToken&)>;
  virtual ~ArtifactCache() = default;
  // Returns the cached value of `key` or builds it with `build` (concurrent
  // callers of one key may share one build). `*hit` tells whether it was
  // already there (or built by another caller). Failed builds are not kept.
  virtual absl::StatusOr<Value> GetOrBuild(const std::string& key, const StopToken& stop,
                                           const Builder& build, bool* hit) = 0;
  // The value of `key` if present (marks it recently used), else null. For
  // entries that are replaced rather than built once (remembered plans).
  virtual Value Find(const std::string& key) = 0;
  // Stores `value` under `key`, replacing what was there, within the budget.
  // Unlike GetOrBuild there is no fence against a concurrent prefix erase:
  // use it only for keys whose text identifies the content (map content id),
  // so that a value put after an erase is still correct, merely cached.
  virtual void Put(const std::string& key, Value value) = 0;
};

// Typed access: builds a T under an ArtifactKey<T>.
template <typename T, typename BuildFn>
absl::StatusOr<std::shared_ptr<const T>> GetOrBuild(ArtifactCache& cache, const ArtifactKey<T>& key,
                                                    const StopToken& stop, BuildFn&& build,
                                                    bool* hit) {
  absl::StatusOr<ArtifactCache::Value> value = cache.GetOrBuild(
      key.text(), stop,
      [&](const StopToken& s) -> absl::StatusOr<ArtifactCache::Value> {
        absl::StatusOr<std::shared_ptr<const T>> built = build(s);
        if (!built.ok()) return built.status();
        return ArtifactCache::Value(std::move(*built));
      },
      hit);
  if (!value.ok()) return value.status();
  std::shared_ptr<const T> typed = std::dynamic_pointer_cast<const T>(*value);
  if (typed == nullptr) {
    return absl::InternalError(
        absl::StrCat("artifact cache: key ", key.text(), " holds another type"));
  }
  return typed;
}

// Keeps every artifact for its lifetime (a one-shot CLI run, a test). No
// single flight: concurrent misses of one key may build twice.
// Thread-safety: thread-safe.
class LocalArtifactCache final : public ArtifactCache {
 public:
  absl::StatusOr<Value> GetOrBuild(const std::string& key, const StopToken& stop,
                                   const Builder& build, bool* hit) override {
    {
      absl::MutexLock lock(&mu_);
      if (auto it = values_.find(key); it != values_.end()) {
        *hit = true;
        return it->second;
      }
    }
    *hit = false;
    absl::StatusOr<Value> built = build(stop);
    if (built.ok() && *built != nullptr) {
      absl::MutexLock lock(&mu_);
      values_.emplace(key, *built);
    }
    return built;
  }
  Value Find(const std::string& key) override {
    absl::MutexLock lock(&mu_);
    auto it = values_.find(key);
    return it == values_.end() ? nullptr : it->second;
  }
  void Put(const std::string& key, Value value) override {
    if (value == nullptr) return;
    absl::MutexLock lock(&mu_);
    values_[key] = std::move(value);
  }
  size_t size() const {
    absl::MutexLock lock(&mu_);
    return values_.size();
  }

 private:
  mutable absl::Mutex mu_;
  std::unordered_map<std::string, Value> values_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_ARTIFACT_CACHE_H_
