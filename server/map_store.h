// The embedded on-disk map registry behind PutMap / GetMap / ListMaps /
// DeleteMap.
//
// One file per map, `<dir>/<map_id>.map`:
//   line 1: "covplan-map 1"
//   line 2: SHA-256 (hex) of the payload
//   line 3: payload size in bytes
//   then the payload: a serialized v1::GetMapResponse (info + map content).
// Writes go to a temporary file that is fsync'ed and renamed over the final
// name (then the directory is fsync'ed), so a crash leaves either the old
// state or the complete new file. Every read verifies the checksum: a
// damaged file is reported (DataLoss, listed as corrupted), never served.
// Open takes an exclusive flock on `<dir>/.lock` for the store's lifetime, so
// a second server on the same directory fails to start. Only regular files
// are read. Errors returned to callers name no server paths (they are
// logged); a full disk is ResourceExhausted, an unwritable store Unavailable.
//
//   ASSIGN_OR_RETURN(std::unique_ptr<MapStore> store, MapStore::Open("./covplan-data/maps"));
//   ASSIGN_OR_RETURN(bool created, store->Put(info, map));
//   ASSIGN_OR_RETURN(v1::GetMapResponse stored, store->Get(map_id));
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_MAP_STORE_H_
#define COVPLAN_SERVER_MAP_STORE_H_

#include <atomic>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "covplan/v1/covplan.pb.h"
#include "server/map_repository.h"

namespace covplan {

class MapStore : public MapRepository {
 public:
  // Creates `dir` if needed, locks it and indexes (and verifies) the maps in
  // it. FailedPrecondition if another process holds the lock.
  static absl::StatusOr<std::unique_ptr<MapStore>> Open(const std::string& dir);
  // Locks `dir`; with index=false, leaves the index to LoadIndex (e.g. on a
  // background thread while the server already answers health). Until it
  // has run, the map methods return Unavailable.
  static absl::StatusOr<std::unique_ptr<MapStore>> OpenLocked(const std::string& dir, bool index);
  // Reads and verifies every map file; `stop` (optional) ends it early.
  absl::Status LoadIndex(const std::atomic<bool>* stop) override;
  bool loading() const override;
  ~MapStore();
  MapStore(const MapStore&) = delete;
  MapStore& operator=(const MapStore&) = delete;

  // Stores the map under info.map_id(). Returns false when an intact copy was
  // already stored (idempotent); a corrupted or missing copy is replaced,
  // even one that was intact when indexed.
  absl::StatusOr<bool> Put(const v1::MapInfo& info, const v1::Map& map) override;

  // NotFound for an unknown id, DataLoss for a damaged file.
  absl::StatusOr<v1::GetMapResponse> Get(const std::string& map_id) const override;

  // Metadata of every intact map (sorted by id); `corrupted` (optional)
  // receives the ids of damaged files.
  std::vector<v1::MapInfo> List(std::vector<std::string>* corrupted) const override;
  // At most `limit` maps with ids after `after` ("" = from the start);
  // `more` says whether any follow.
  absl::StatusOr<std::vector<v1::MapInfo>> ListPage(
      const std::string& after, int limit, bool* more,
      std::vector<std::string>* corrupted) const override;

  // Returns false if there was no such map. The map stays indexed when the
  // file cannot be removed.
  absl::StatusOr<bool> Delete(const std::string& map_id) override;

  // From the in-memory index only (no disk access): OK if the map is
  // indexed and not known to be damaged, else NotFound / DataLoss.
  absl::Status Check(const std::string& map_id) const override;

  // Writes and renames a small probe file; updates writable().
  absl::Status ProbeWritable() override;
  // False after a write failed for lack of space or permission, until one
  // succeeds again.
  bool writable() const override { return writable_.load(); }

  int64_t size() const override;
  const std::string& dir() const { return dir_; }

  // Small server state beside the maps (e.g. the replan estimator), written
  // atomically. IsStateName(name). NotFound if absent.
  absl::Status PutState(const std::string& name, absl::string_view contents) override;
  absl::StatusOr<std::string> GetState(const std::string& name) const override;

  // Retained plans, so a mission survives a restart: one file per plan id
  // under plans/, written atomically. `plan_id` is [a-z0-9-]{1,64}.
  // NotFound when absent. TrimPlans keeps the newest `keep` files.
  absl::Status PutPlan(const std::string& plan_id, absl::string_view contents) override;
  // Each written to a temporary file, one syncfs, the renames, one
  // directory fsync: two syncs for the lot instead of two per record.
  absl::Status PutPlans(const std::vector<std::pair<std::string, std::string>>& plans) override;
  absl::StatusOr<std::string> GetPlan(const std::string& plan_id) const override;
  int64_t TrimPlans(int64_t keep) override;
  absl::Status TouchPlan(const std::string& plan_id) override;
  // The robot's last reported progress on a plan (plans/<plan_id>.progress),
  // written atomically; NotFound when none was recorded.
  absl::Status PutProgress(const std::string& plan_id, absl::string_view contents) override;
  absl::StatusOr<std::string> GetProgress(const std::string& plan_id) const override;

 private:
  explicit MapStore(std::string dir) : dir_(std::move(dir)) {}
  std::string PathFor(const std::string& map_id) const;
  absl::StatusOr<v1::GetMapResponse> ReadVerified(const std::string& path) const;
  void MarkCorrupted(const std::string& map_id) const;

  const std::string dir_;
  int lock_fd_ = -1;
  std::atomic<bool> writable_{true};
  mutable absl::Mutex mu_;
  // Serialises writers of the same directory so Put/Delete races stay ordered.
  absl::Mutex write_mu_ ABSL_ACQUIRED_BEFORE(mu_);
  mutable std::map<std::string, v1::MapInfo> index_ ABSL_GUARDED_BY(mu_);
  mutable std::set<std::string> corrupted_ ABSL_GUARDED_BY(mu_);
  bool loading_ ABSL_GUARDED_BY(mu_) = false;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_MAP_STORE_H_
