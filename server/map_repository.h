// The map registry as the service sees it: maps, small server state and
// retained plans. Two implementations: the embedded on-disk `MapStore`
// (server/map_store.h, the default) and the shared `PgMapStore`
// (server/pg_map_store.h), selected by covplan-server --map_store.
//
//   std::unique_ptr<MapRepository> store = ...;  // MapStore::Open / PgMapStore::Open
//   ASSIGN_OR_RETURN(bool created, store->Put(info, map));
//   ASSIGN_OR_RETURN(v1::GetMapResponse stored, store->Get(map_id));
//
// Errors: NotFound for unknown ids, DataLoss for a copy that fails its
// checksum, Unavailable (with the reason) when a remote store cannot be
// reached; the caller passes these on as the gRPC status.
//
// Thread-safety: implementations are thread-safe.
#ifndef COVPLAN_SERVER_MAP_REPOSITORY_H_
#define COVPLAN_SERVER_MAP_REPOSITORY_H_

#include <atomic>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/string_view.h"
#include "covplan/v1/covplan.pb.h"

namespace covplan {

// The names a store accepts: state names are [a-z0-9_]+ with a ".txt"
// suffix; plan ids are [a-z0-9-]{1,64}.
inline bool IsStateName(absl::string_view name) {
  if (name.size() < 5 || !absl::EndsWith(name, ".txt")) return false;
  for (char c : name.substr(0, name.size() - 4)) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}
inline bool IsPlanId(absl::string_view id) {
  if (id.empty() || id.size() > 64) return false;
  for (char c : id) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-')) return false;
  }
  return true;
}

class MapRepository {
 public:
  virtual ~MapRepository() = default;

  // Stores the map under info.map_id(). Returns false when an intact copy was
  // already stored (idempotent); a corrupted copy is replaced.
  virtual absl::StatusOr<bool> Put(const v1::MapInfo& info, const v1::Map& map) = 0;
  virtual absl::StatusOr<v1::GetMapResponse> Get(const std::string& map_id) const = 0;
  // Metadata of every intact map (sorted by id); `corrupted` (optional)
  // receives the ids of damaged copies. A store that cannot be reached
  // lists nothing; Available() says why.
  virtual std::vector<v1::MapInfo> List(std::vector<std::string>* corrupted) const = 0;
  // Returns false if there was no such map.
  virtual absl::StatusOr<bool> Delete(const std::string& map_id) = 0;
  // Maps stored (the last known count while a remote store is unreachable).
  virtual int64_t size() const = 0;

  // Small server state (e.g. the replan estimator): IsStateName(name).
  virtual absl::Status PutState(const std::string& name, absl::string_view contents) = 0;
  virtual absl::StatusOr<std::string> GetState(const std::string& name) const = 0;

  // Retained plans, so a mission survives a restart. IsPlanId(plan_id). TrimPlans keeps the newest
  // `keep` and returns how many it removed.
  virtual absl::Status PutPlan(const std::string& plan_id, absl::string_view contents) = 0;
  // Several small records at once (a store may sync them together); the
  // first error, after trying them all.
  virtual absl::Status PutPlans(const std::vector<std::pair<std::string, std::string>>& plans) {
    absl::Status first;
    for (const auto& [id, contents] : plans) first.Update(PutPlan(id, contents));
    return first;
  }
  virtual absl::StatusOr<std::string> GetPlan(const std::string& plan_id) const = 0;
  virtual int64_t TrimPlans(int64_t keep) = 0;
  // Makes a stored plan the newest for TrimPlans (a plan that newer records
  // name, such as a repeated hit's alias, is trimmed after them).
  virtual absl::Status TouchPlan(const std::string& plan_id) = 0;

  // OK when the store can serve now; Unavailable with the reason otherwise.
  virtual absl::Status Available() const { return absl::OkStatus(); }

  // A page of List: at most `limit` maps with ids after `after` ("" = from
  // the start); `more` says whether any follow. Unavailable when the store
  // cannot be reached (rather than an empty page).
  virtual absl::StatusOr<std::vector<v1::MapInfo>> ListPage(
      const std::string& after, int limit, bool* more, std::vector<std::string>* corrupted) const;
  // A cheap check before serving a map from the cache: OK unless the store
  // knows the map is gone or damaged. Stores without an in-memory index
  // answer OK (their Get verifies every read).
  virtual absl::Status Check(const std::string& map_id) const { return absl::OkStatus(); }
  // Tries a small write; writable() reports the outcome (health, metrics).
  virtual absl::Status ProbeWritable() { return Available(); }
  virtual bool writable() const { return Available().ok(); }
  // Stores whose index loads in the background (the disk store at startup).
  virtual bool loading() const { return false; }
  virtual absl::Status LoadIndex(const std::atomic<bool>* stop) { return absl::OkStatus(); }

  // The robot's last reported progress on a plan, for Resume. By default
  // kept beside the plans under the id "<plan_id>-progress".
  virtual absl::Status PutProgress(const std::string& plan_id, absl::string_view contents) {
    return PutPlan(plan_id + "-progress", contents);
  }
  virtual absl::StatusOr<std::string> GetProgress(const std::string& plan_id) const {
    return GetPlan(plan_id + "-progress");
  }
};

inline absl::StatusOr<std::vector<v1::MapInfo>> MapRepository::ListPage(
    const std::string& after, int limit, bool* more, std::vector<std::string>* corrupted) const {
  if (absl::Status s = Available(); !s.ok()) return s;
  std::vector<v1::MapInfo> all = List(corrupted);
  std::vector<v1::MapInfo> page;
  *more = false;
  for (v1::MapInfo& info : all) {  // List is sorted by id
    if (!after.empty() && info.map_id() <= after) continue;
    if (static_cast<int>(page.size()) == limit) {
      *more = true;
      break;
    }
    page.push_back(std::move(info));
  }
  return page;
}

}  // namespace covplan

#endif  // COVPLAN_SERVER_MAP_REPOSITORY_H_
