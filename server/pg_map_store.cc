#include "server/pg_map_store.h"

#include <libpq-fe.h>

#include <algorithm>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "api/digest.h"
#include "server/log.h"

namespace covplan {
namespace {

// Maps whose presence Check remembers at most (then it starts afresh).
constexpr size_t kMaxChecked = 4096;

constexpr char kSchema[] =
    "BEGIN;"
    "SELECT pg_advisory_xact_lock(726501);"
    "CREATE TABLE IF NOT EXISTS covplan_maps ("
    "  map_id text PRIMARY KEY, sha256 text NOT NULL, info bytea NOT NULL,"
    "  payload bytea NOT NULL, created timestamptz NOT NULL DEFAULT now());"
    "CREATE TABLE IF NOT EXISTS covplan_state ("
    "  name text PRIMARY KEY, contents bytea NOT NULL);"
    "CREATE TABLE IF NOT EXISTS covplan_plans ("
    "  plan_id text PRIMARY KEY, contents bytea NOT NULL,"
    "  created timestamptz NOT NULL DEFAULT clock_timestamp());"
    "CREATE INDEX IF NOT EXISTS covplan_plans_created ON covplan_plans (created);"
    "COMMIT;";

struct ResultDeleter {
  void operator()(PGresult* r) const { PQclear(r); }
};
using Result = std::unique_ptr<PGresult, ResultDeleter>;

// One statement parameter: text (NUL-terminated) or binary (bytea).
struct Param {
  absl::string_view data;
  bool binary = false;
};

std::string Reason(PGconn* conn) {
  return std::string(
      absl::StripTrailingAsciiWhitespace(conn ? PQerrorMessage(conn) : "out of memory"));
}

absl::Status Unavailable(const std::string& reason) {
  return absl::UnavailableError(absl::StrCat("map store (PostgreSQL) unavailable: ", reason));
}

std::string Field(PGresult* r, int row, int col) {
  return std::string(PQgetvalue(r, row, col), PQgetlength(r, row, col));
}

}  // namespace

// A libpq connection that reconnects when it finds itself broken.
class PgConnection {
 public:
  explicit PgConnection(const std::string& conninfo, int statement_timeout_ms)
      : conninfo_(conninfo), statement_timeout_ms_(statement_timeout_ms) {}
  ~PgConnection() {
    if (conn_ != nullptr) PQfinish(conn_);
  }

  // Connects (again) if needed and makes sure the schema exists.
  absl::Status Ensure() {
    if (conn_ != nullptr && PQstatus(conn_) == CONNECTION_OK) return absl::OkStatus();
    if (conn_ != nullptr) PQfinish(conn_);
    schema_ready_ = false;
    conn_ = PQconnectdb(conninfo_.c_str());
    if (conn_ == nullptr || PQstatus(conn_) != CONNECTION_OK) return Unavailable(Reason(conn_));
    const std::string setup =
        absl::StrCat("SET statement_timeout = ", statement_timeout_ms_, ";", kSchema);
    Result r(PQexec(conn_, setup.c_str()));
    if (PQresultStatus(r.get()) != PGRES_COMMAND_OK) return Failure(r.get());
    schema_ready_ = true;
    return absl::OkStatus();
  }

  // Runs one statement. `retry`: the statement may run again on a fresh
  // connection if the old one turns out broken (not inside a transaction).
  absl::StatusOr<Result> Exec(const char* sql, const std::vector<Param>& params, bool retry,
                              bool binary_result = true) {
    for (int attempt = 0;; ++attempt) {
      if (absl::Status s = Ensure(); !s.ok()) return s;
      std::vector<const char*> values;
      std::vector<int> lengths, formats;
      for (const Param& p : params) {
        values.push_back(p.data.data());
        lengths.push_back(static_cast<int>(p.data.size()));
        formats.push_back(p.binary ? 1 : 0);
      }
      Result r(PQexecParams(conn_, sql, static_cast<int>(params.size()), nullptr, values.data(),
                            lengths.data(), formats.data(), binary_result ? 1 : 0));
      const ExecStatusType status = PQresultStatus(r.get());
      if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return r;
      if (retry && attempt == 0 && PQstatus(conn_) != CONNECTION_OK) continue;
      return Failure(r.get());
    }
  }

 private:
  absl::Status Failure(PGresult* r) {
    if (PQstatus(conn_) != CONNECTION_OK) return Unavailable(Reason(conn_));
    const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
    const std::string message(
        absl::StripTrailingAsciiWhitespace(r ? PQresultErrorMessage(r) : Reason(conn_)));
    // 57014 query_canceled (statement_timeout), 57P0x shutdown, 08xxx
    // connection exceptions, 53xxx insufficient resources: the database, not
    // the request.
    if (state != nullptr && (absl::StartsWith(state, "57") || absl::StartsWith(state, "08") ||
                             absl::StartsWith(state, "53"))) {
      return Unavailable(message);
    }
    return absl::InternalError(absl::StrCat("map store (PostgreSQL): ", message));
  }

  const std::string conninfo_;
  const int statement_timeout_ms_;
  PGconn* conn_ = nullptr;
  bool schema_ready_ = false;
};

// A connection borrowed from the pool for one call.
class PgMapStore::Lease {
 public:
  Lease(const PgMapStore* store, std::unique_ptr<PgConnection> c)
      : store_(store), connection_(std::move(c)) {}
  Lease(Lease&& other) noexcept : store_(other.store_), connection_(std::move(other.connection_)) {}
  ~Lease() {
    if (connection_ != nullptr) store_->Release(std::move(connection_));
  }
  PgConnection* operator->() { return connection_.get(); }

 private:
  const PgMapStore* store_;
  std::unique_ptr<PgConnection> connection_;
};

PgMapStore::PgMapStore(std::string conninfo, PgMapStoreOptions options)
    : conninfo_(std::move(conninfo)), options_(options) {}
PgMapStore::~PgMapStore() = default;

absl::StatusOr<std::unique_ptr<PgMapStore>> PgMapStore::Open(const std::string& conninfo,
                                                             PgMapStoreOptions options) {
  if (options.connections < 1)
    return absl::InvalidArgumentError("PostgreSQL pool needs >= 1 connection");
  char* error = nullptr;
  PQconninfoOption* parsed = PQconninfoParse(conninfo.c_str(), &error);
  if (parsed == nullptr) {
    const std::string reason =
        error ? std::string(absl::StripTrailingAsciiWhitespace(error)) : "out of memory";
    PQfreemem(error);
    return absl::InvalidArgumentError(absl::StrCat("--pg_conninfo: ", reason));
  }
  PQconninfoFree(parsed);
  std::unique_ptr<PgMapStore> store(new PgMapStore(conninfo, options));
  if (absl::Status s = store->Available(); !s.ok()) {
    LogLine("warn", "map store not reachable yet; serving UNAVAILABLE until it is",
            {{"reason", std::string(s.message())}});
  } else {
    store->size();  // primes the count
  }
  return store;
}

absl::StatusOr<PgMapStore::Lease> PgMapStore::Acquire() const {
  std::unique_ptr<PgConnection> connection;
  {
    absl::MutexLock lock(&mu_);
    while (idle_.empty() && leased_ >= options_.connections) released_.Wait(&mu_);
    if (!idle_.empty()) {
      connection = std::move(idle_.back());
      idle_.pop_back();
    }
    ++leased_;
  }
  if (connection == nullptr) {
    connection = std::make_unique<PgConnection>(conninfo_, options_.statement_timeout_ms);
  }
  Lease lease(this, std::move(connection));
  if (absl::Status s = lease->Ensure(); !s.ok()) return s;
  return lease;
}

void PgMapStore::Release(std::unique_ptr<PgConnection> connection) const {
  absl::MutexLock lock(&mu_);
  idle_.push_back(std::move(connection));
  --leased_;
  released_.Signal();
}

absl::Status PgMapStore::Available() const {
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  return (*c)->Exec("SELECT 1", {}, true).status();
}

absl::StatusOr<bool> PgMapStore::Put(const v1::MapInfo& info, const v1::Map& map) {
  v1::GetMapResponse record;
  *record.mutable_info() = info;
  *record.mutable_map() = map;
  const std::string payload = record.SerializeAsString();
  const std::string sha = Sha256Hex(payload);
  const std::string info_bytes = info.SerializeAsString();
  const std::vector<Param> row = {{info.map_id()}, {sha}, {info_bytes, true}, {payload, true}};
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  absl::StatusOr<Result> inserted = (*c)->Exec(
      "INSERT INTO covplan_maps (map_id, sha256, info, payload) VALUES ($1, $2, $3, $4) "
      "ON CONFLICT (map_id) DO NOTHING",
      row, true);
  if (!inserted.ok()) return inserted.status();
  if (std::string(PQcmdTuples(inserted->get())) == "1") {
    ++last_size_;
    return true;
  }
  // Already there: keep an intact copy, replace a damaged one, in one
  // transaction so two replicas repairing at once do not interleave.
  if (auto s = (*c)->Exec("BEGIN", {}, true); !s.ok()) return s.status();
  absl::StatusOr<Result> existing =
      (*c)->Exec("SELECT sha256, payload FROM covplan_maps WHERE map_id = $1 FOR UPDATE",
                 {{info.map_id()}}, false);
  bool intact = false;
  if (existing.ok() && PQntuples(existing->get()) == 1) {
    intact = Sha256Hex(Field(existing->get(), 0, 1)) == Field(existing->get(), 0, 0);
  }
  absl::Status written = existing.status();
  if (written.ok() && !intact) {
    written =
        (*c)->Exec(
                "INSERT INTO covplan_maps (map_id, sha256, info, payload) VALUES ($1, $2, $3, $4) "
                "ON CONFLICT (map_id) DO UPDATE SET sha256 = EXCLUDED.sha256, "
                "info = EXCLUDED.info, payload = EXCLUDED.payload",
                row, false)
            .status();
    if (written.ok()) LogLine("warn", "replaced a damaged map copy", {{"map_id", info.map_id()}});
  }
  absl::StatusOr<Result> end = (*c)->Exec(written.ok() ? "COMMIT" : "ROLLBACK", {}, false);
  if (!written.ok()) return written;
  if (!end.ok()) return end.status();
  return !intact;
}

absl::StatusOr<v1::GetMapResponse> PgMapStore::Get(const std::string& map_id) const {
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  absl::StatusOr<Result> r =
      (*c)->Exec("SELECT sha256, payload FROM covplan_maps WHERE map_id = $1", {{map_id}}, true);
  if (!r.ok()) return r.status();
  if (PQntuples(r->get()) == 0)
    return absl::NotFoundError(absl::StrCat("no map ", map_id.substr(0, 80)));
  const std::string payload = Field(r->get(), 0, 1);
  v1::GetMapResponse record;
  if (Sha256Hex(payload) != Field(r->get(), 0, 0) || !record.ParseFromString(payload)) {
    return absl::DataLossError(absl::StrCat("stored map ", map_id, " fails its checksum"));
  }
  return record;
}

std::vector<v1::MapInfo> PgMapStore::List(std::vector<std::string>* corrupted) const {
  std::vector<v1::MapInfo> out;
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return out;
  absl::StatusOr<Result> r = (*c)->Exec(
      "SELECT map_id, info, encode(sha256(payload), 'hex') = sha256 FROM covplan_maps "
      "ORDER BY map_id",
      {}, true);
  if (!r.ok()) return out;
  for (int i = 0; i < PQntuples(r->get()); ++i) {
    v1::MapInfo info;
    const bool intact = PQgetlength(r->get(), i, 2) == 1 && PQgetvalue(r->get(), i, 2)[0] == 1;
    if (intact && info.ParseFromString(Field(r->get(), i, 1))) {
      out.push_back(std::move(info));
    } else if (corrupted != nullptr) {
      corrupted->push_back(Field(r->get(), i, 0));
    }
  }
  return out;
}

absl::StatusOr<bool> PgMapStore::Delete(const std::string& map_id) {
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  absl::StatusOr<Result> r =
      (*c)->Exec("DELETE FROM covplan_maps WHERE map_id = $1", {{map_id}}, true);
  if (!r.ok()) return r.status();
  const bool deleted = std::string(PQcmdTuples(r->get())) == "1";
  if (deleted) --last_size_;
  absl::MutexLock lock(&checked_mu_);
  checked_.erase(map_id);
  return deleted;
}

absl::Status PgMapStore::Check(const std::string& map_id) const {
  const absl::Time now = absl::Now();
  {
    absl::MutexLock lock(&checked_mu_);
    const auto it = checked_.find(map_id);
    if (it != checked_.end() && now - it->second < options_.check_ttl) return absl::OkStatus();
  }
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return absl::OkStatus();
  absl::StatusOr<Result> r =
      (*c)->Exec("SELECT 1 FROM covplan_maps WHERE map_id = $1", {{map_id}}, true, false);
  if (!r.ok()) return absl::OkStatus();
  const bool present = PQntuples(r->get()) == 1;
  absl::MutexLock lock(&checked_mu_);
  if (!present) {
    checked_.erase(map_id);
    return absl::NotFoundError(absl::StrCat("no map ", map_id.substr(0, 80)));
  }
  if (checked_.size() >= kMaxChecked) checked_.clear();
  checked_[map_id] = now;
  return absl::OkStatus();
}

int64_t PgMapStore::size() const {
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return last_size_.load();
  absl::StatusOr<Result> r = (*c)->Exec("SELECT count(*) FROM covplan_maps", {}, true, false);
  int64_t n = 0;
  if (r.ok() && PQntuples(r->get()) == 1 && absl::SimpleAtoi(PQgetvalue(r->get(), 0, 0), &n)) {
    last_size_.store(n);
  }
  return last_size_.load();
}

absl::Status PgMapStore::PutState(const std::string& name, absl::string_view contents) {
  if (!IsStateName(name))
    return absl::InvalidArgumentError(absl::StrCat("bad state file name ", name));
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  return (*c)
      ->Exec(
          "INSERT INTO covplan_state (name, contents) VALUES ($1, $2) "
          "ON CONFLICT (name) DO UPDATE SET contents = EXCLUDED.contents",
          {{name}, {contents, true}}, true)
      .status();
}

absl::StatusOr<std::string> PgMapStore::GetState(const std::string& name) const {
  if (!IsStateName(name))
    return absl::InvalidArgumentError(absl::StrCat("bad state file name ", name));
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  absl::StatusOr<Result> r =
      (*c)->Exec("SELECT contents FROM covplan_state WHERE name = $1", {{name}}, true);
  if (!r.ok()) return r.status();
  if (PQntuples(r->get()) == 0) return absl::NotFoundError(absl::StrCat("no state ", name));
  return Field(r->get(), 0, 0);
}

absl::Status PgMapStore::PutPlan(const std::string& plan_id, absl::string_view contents) {
  if (!IsPlanId(plan_id)) return absl::InvalidArgumentError(absl::StrCat("bad plan id ", plan_id));
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  return (*c)
      ->Exec(
          "INSERT INTO covplan_plans (plan_id, contents) VALUES ($1, $2) "
          "ON CONFLICT (plan_id) DO UPDATE SET contents = EXCLUDED.contents, "
          "created = clock_timestamp()",
          {{plan_id}, {contents, true}}, true)
      .status();
}

absl::StatusOr<std::string> PgMapStore::GetPlan(const std::string& plan_id) const {
  if (!IsPlanId(plan_id))
    return absl::NotFoundError(absl::StrCat("no plan ", plan_id.substr(0, 80)));
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  absl::StatusOr<Result> r =
      (*c)->Exec("SELECT contents FROM covplan_plans WHERE plan_id = $1", {{plan_id}}, true);
  if (!r.ok()) return r.status();
  if (PQntuples(r->get()) == 0)
    return absl::NotFoundError(absl::StrCat("no stored plan ", plan_id));
  return Field(r->get(), 0, 0);
}

absl::Status PgMapStore::TouchPlan(const std::string& plan_id) {
  if (!IsPlanId(plan_id))
    return absl::NotFoundError(absl::StrCat("no plan ", plan_id.substr(0, 80)));
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return c.status();
  absl::StatusOr<Result> r = (*c)->Exec(
      "UPDATE covplan_plans SET created = clock_timestamp() WHERE plan_id = $1", {{plan_id}}, true);
  if (!r.ok()) return r.status();
  if (std::string(PQcmdTuples(r->get())) == "0")
    return absl::NotFoundError(absl::StrCat("no stored plan ", plan_id));
  return absl::OkStatus();
}

int64_t PgMapStore::TrimPlans(int64_t keep) {
  absl::StatusOr<Lease> c = Acquire();
  if (!c.ok()) return 0;
  const std::string offset = absl::StrCat(std::max<int64_t>(0, keep));
  absl::StatusOr<Result> r = (*c)->Exec(
      "DELETE FROM covplan_plans WHERE plan_id IN "
      "(SELECT plan_id FROM covplan_plans ORDER BY created DESC OFFSET $1::bigint)",
      {{offset}}, true);
  int64_t removed = 0;
  if (r.ok()) (void)absl::SimpleAtoi(PQcmdTuples(r->get()), &removed);
  return removed;
}

}  // namespace covplan
