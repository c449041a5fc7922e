// A map registry in PostgreSQL, shared by every covplan-server replica:
// a map PutMap'ed on one replica is readable by all, and a replica started
// later serves every registered map. Selected by --map_store=postgres
// --pg_conninfo="host=... dbname=..."; the embedded disk store stays the
// default.
//
// Tables (created on first connect, under an advisory lock so replicas
// starting together do not race):
//   covplan_maps(map_id text primary key, sha256 text, info bytea, payload bytea)
//     payload: a serialized v1::GetMapResponse (info + map), sha256 its hex
//     digest, verified on every read (DataLoss when it does not match);
//   covplan_state(name text primary key, contents bytea)
//   covplan_plans(plan_id text primary key, contents bytea, created timestamptz)
// Every write is one transaction (a repair of a damaged copy is
// SELECT ... FOR UPDATE + UPDATE in one).
//
// The database being down or unreachable is Unavailable("map store
// (PostgreSQL) unavailable: <libpq's reason>"), never a crash; every call
// reconnects if the connection was lost, so the store recovers by itself
// when the database returns. Open() succeeds even when the database is down
// (the replica starts and reports Unavailable until it is back), but fails
// on a malformed conninfo.
//
//   ASSIGN_OR_RETURN(std::unique_ptr<PgMapStore> store,
//                    PgMapStore::Open("host=/tmp/pg port=5432 dbname=covplan"));
//
// Thread-safety: all methods are thread-safe. Calls share a small pool of
// connections (each used by one call at a time).
#ifndef COVPLAN_SERVER_PG_MAP_STORE_H_
#define COVPLAN_SERVER_PG_MAP_STORE_H_

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/map_repository.h"

namespace covplan {

class PgConnection;

struct PgMapStoreOptions {
  int connections = 4;              // pool size
  int statement_timeout_ms = 5000;  // per statement, so a hung database cannot hold a worker
  // How long a map found present stays known present to Check: the bound
  // within which a map deleted through another replica stops being planned
  // from this replica's cache.
  absl::Duration check_ttl = absl::Seconds(1);
};

class PgMapStore : public MapRepository {
 public:
  static absl::StatusOr<std::unique_ptr<PgMapStore>> Open(const std::string& conninfo,
                                                          PgMapStoreOptions options = {});
  ~PgMapStore() override;

  absl::StatusOr<bool> Put(const v1::MapInfo& info, const v1::Map& map) override;
  absl::StatusOr<v1::GetMapResponse> Get(const std::string& map_id) const override;
  std::vector<v1::MapInfo> List(std::vector<std::string>* corrupted) const override;
  absl::StatusOr<bool> Delete(const std::string& map_id) override;
  int64_t size() const override;
  absl::Status PutState(const std::string& name, absl::string_view contents) override;
  absl::StatusOr<std::string> GetState(const std::string& name) const override;
  absl::Status PutPlan(const std::string& plan_id, absl::string_view contents) override;
  absl::StatusOr<std::string> GetPlan(const std::string& plan_id) const override;
  int64_t TrimPlans(int64_t keep) override;
  absl::Status TouchPlan(const std::string& plan_id) override;
  absl::Status Available() const override;
  // NotFound once the map's row is gone (looked up at most every check_ttl
  // per map, so a delete on any replica holds here within that bound); OK
  // when the database cannot be reached (the cached map is the best
  // knowledge).
  absl::Status Check(const std::string& map_id) const override;

 private:
  class Lease;
  PgMapStore(std::string conninfo, PgMapStoreOptions options);
  // A connected connection with the schema in place, or Unavailable.
  absl::StatusOr<Lease> Acquire() const;
  void Release(std::unique_ptr<PgConnection> connection) const;

  const std::string conninfo_;
  const PgMapStoreOptions options_;
  mutable absl::Mutex mu_;
  mutable absl::CondVar released_;
  mutable std::vector<std::unique_ptr<PgConnection>> idle_ ABSL_GUARDED_BY(mu_);
  mutable int leased_ ABSL_GUARDED_BY(mu_) = 0;
  mutable std::atomic<int64_t> last_size_{0};
  // When each map was last found present (for Check).
  mutable absl::Mutex checked_mu_;
  mutable absl::flat_hash_map<std::string, absl::Time> checked_ ABSL_GUARDED_BY(checked_mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_PG_MAP_STORE_H_
