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
//
//   ASSIGN_OR_RETURN(std::unique_ptr<MapStore> store, MapStore::Open("./covplan-data/maps"));
//   ASSIGN_OR_RETURN(bool created, store->Put(info, map));
//   ASSIGN_OR_RETURN(v1::GetMapResponse stored, store->Get(map_id));
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_MAP_STORE_H_
#define COVPLAN_SERVER_MAP_STORE_H_

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
  // Creates `dir` if needed and indexes (and verifies) the maps in it.
  static absl::StatusOr<std::unique_ptr<MapStore>> Open(const std::string& dir);

  // Stores the map under info.map_id(). Returns false when an intact copy was
  // already stored (idempotent); a corrupted copy is replaced.
  absl::StatusOr<bool> Put(const v1::MapInfo& info, const v1::Map& map) override;

  // NotFound for an unknown id, DataLoss for a damaged file.
  absl::StatusOr<v1::GetMapResponse> Get(const std::string& map_id) const override;

  // Metadata of every intact map (sorted by id); `corrupted` (optional)
  // receives the ids of damaged files.
  std::vector<v1::MapInfo> List(std::vector<std::string>* corrupted) const override;

  // Returns false if there was no such map.
  absl::StatusOr<bool> Delete(const std::string& map_id) override;

  int64_t size() const override;
  const std::string& dir() const { return dir_; }

  // Small server state beside the maps (e.g. the replan estimator), written
  // atomically. `name` is [a-z_]+ with a ".txt" suffix. NotFound if absent.
  absl::Status PutState(const std::string& name, absl::string_view contents) override;
  absl::StatusOr<std::string> GetState(const std::string& name) const override;

  // Retained plans, so a mission survives a restart: one file per plan id
  // under plans/, written atomically. `plan_id` is [a-z0-9-]{1,64}.
  // NotFound when absent. TrimPlans keeps the newest `keep` files.
  absl::Status PutPlan(const std::string& plan_id, absl::string_view contents) override;
  absl::StatusOr<std::string> GetPlan(const std::string& plan_id) const override;
  int64_t TrimPlans(int64_t keep) override;

 private:
  explicit MapStore(std::string dir) : dir_(std::move(dir)) {}
  std::string PathFor(const std::string& map_id) const;
  absl::StatusOr<v1::GetMapResponse> ReadVerified(const std::string& path) const;
  void MarkCorrupted(const std::string& map_id) const;

  const std::string dir_;
  mutable absl::Mutex mu_;
  // Serialises writers of the same directory so Put/Delete races stay ordered.
  absl::Mutex write_mu_ ABSL_ACQUIRED_BEFORE(mu_);
  mutable std::map<std::string, v1::MapInfo> index_ ABSL_GUARDED_BY(mu_);
  mutable std::set<std::string> corrupted_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_MAP_STORE_H_
