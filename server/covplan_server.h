// A running covplan server: the gRPC service (with health and reflection),
// the on-disk map store and the Prometheus /metrics endpoint, started and
// drained as one unit. Used by covplan-server's main and by the in-process
// tests.
//
//   ServerConfig config;
//   config.port = 0;  // pick a free port
//   ASSIGN_OR_RETURN(std::unique_ptr<CovplanServer> server, CovplanServer::Start(config));
//   Connect(absl::StrCat("127.0.0.1:", server->port()));
//   server->Drain(absl::Seconds(10));  // NOT_SERVING, finish in-flight calls, stop
//
// Thread-safety: Drain may be called from any thread, once or more.
#ifndef COVPLAN_SERVER_COVPLAN_SERVER_H_
#define COVPLAN_SERVER_COVPLAN_SERVER_H_

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/http_gateway.h"
#include "server/service.h"

namespace grpc {
class Server;
}
namespace prometheus {
class Collectable;
class Exposer;
}  // namespace prometheus

namespace covplan {

struct ServerConfig {
  std::string address = "127.0.0.1";
  int port = 50051;  // 0: pick a free port
  std::string metrics_address = "127.0.0.1";
  int metrics_port = 9464;  // 0: pick a free port; -1: no metrics endpoint
  std::string store_dir = "./covplan-data/maps";
  // "disk" (the embedded store in store_dir, default) or "postgres" (shared
  // by replicas; pg_conninfo is a libpq connection string).
  std::string map_store = "disk";
  std::string pg_conninfo;
  int max_message_bytes = 80 << 20;  // largest request accepted
  // On Drain, how long health reports NOT_SERVING (and new work is refused)
  // before the listener closes, so load balancers see it.
  absl::Duration drain_notice = absl::ZeroDuration();
  // How often the store is probed for writes; the result is the health of
  // kStoreHealthService and the covplan_store_writable gauge.
  absl::Duration store_probe_interval = absl::Seconds(2);  // also the files' reread bound
  // Index the store on a background thread after the port is open, with
  // health NOT_SERVING (and map calls UNAVAILABLE) until it is done, so a
  // large store does not keep the port closed. Off: Start indexes first.
  bool index_in_background = false;
  // TLS on the gRPC port: PEM files of the server's certificate chain and
  // key (both or neither; neither = plaintext). With a client CA, clients
  // must present a certificate it signed (mutual TLS).
  std::string tls_cert_file;
  std::string tls_key_file;
  std::string tls_client_ca_file;
  // Bearer tokens (server/tenant_tokens.h): with a file, every
  // CoveragePlanner call needs a token of a tenant (health and reflection
  // stay open) and sees only that tenant's maps and plans. Empty: open.
  std::string token_file;
  // Per-tenant quota overrides (server/tenant_quotas.h) over
  // service.tenant_quota; reread on SIGHUP. Empty: the defaults for all.
  std::string tenant_quota_file;
  // The JSON API (server/http_gateway.h): -1 off (the default), 0 picks a
  // free port.
  std::string http_address = "127.0.0.1";
  int http_port = -1;
  // A client slower than this to send its request is cut off.
  int http_request_timeout_ms = 15000;
  ServiceOptions service;
};

// The gRPC health service name that reports whether the map store accepts
// writes (NOT_SERVING when it is full or read-only; plans on stored maps
// still work, so the server as a whole ("") stays SERVING).
inline constexpr char kStoreHealthService[] = "covplan.v1.MapStore";

class CovplanServer {
 public:
  // Fails clearly when a port is taken or the store cannot be opened.
  static absl::StatusOr<std::unique_ptr<CovplanServer>> Start(const ServerConfig& config);
  ~CovplanServer();  // Drain(0)

  int port() const { return port_; }
  int metrics_port() const { return metrics_port_; }
  int http_port() const { return http_ != nullptr ? http_->port() : -1; }
  CoveragePlannerService& service() { return *service_; }

  // Reports NOT_SERVING and refuses new work (for the configured drain
  // notice), lets in-flight unary calls finish for up to `grace` in all,
  // then cuts running solves short (they answer with their best plan,
  // marked in termination.detail), gives replies 0.5 s + 0.2 s to leave,
  // cancels what is left (health Watch streams included) and stops.
  void Drain(absl::Duration grace);

  // Rereads the token file (SIGHUP); on error the previous tokens stay and
  // the error is returned. OK and nothing done without a token file.
  absl::Status ReloadTokens() ABSL_LOCKS_EXCLUDED(reload_mu_);
  // Rereads the tenant quota file (SIGHUP) the same way.
  absl::Status ReloadQuotas() ABSL_LOCKS_EXCLUDED(reload_mu_);
  // Rereads the token and quota files whose modification time or size
  // changed since they were last read; the store probe calls it every
  // store_probe_interval, so a file changed on every replica's disk (or
  // its shared volume) takes effect on each within that bound, no SIGHUP
  // needed.
  void ReloadChangedFiles() ABSL_LOCKS_EXCLUDED(reload_mu_);

 private:
  CovplanServer() = default;
  // Logs the corrupted maps and the size of the index.
  void LogIndexed(absl::Duration took);
  // Probes the store every `interval` until Drain.
  void ProbeStoreLoop(absl::Duration interval);

  std::unique_ptr<MapRepository> store_;
  std::unique_ptr<TenantTokens> tokens_;  // null without --token_file
  std::unique_ptr<TenantQuotas> quotas_;
  std::string token_file_;
  std::string quota_file_;
  absl::Status ReloadTokensLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(reload_mu_);
  absl::Status ReloadQuotasLocked() ABSL_EXCLUSIVE_LOCKS_REQUIRED(reload_mu_);
  // Serialises the rereads (the signal thread's and the store probe's), so a
  // SIGHUP's reread also counts as the probe's: the file is read once.
  absl::Mutex reload_mu_;
  // Modification time and size when last read.
  std::string token_stamp_ ABSL_GUARDED_BY(reload_mu_);
  std::string quota_stamp_ ABSL_GUARDED_BY(reload_mu_);
  std::unique_ptr<ServerMetrics> metrics_;
  std::unique_ptr<CoveragePlannerService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<prometheus::Exposer> exposer_;
  std::unique_ptr<HttpGateway> http_;                         // null without an HTTP port
  std::shared_ptr<prometheus::Collectable> process_metrics_;  // registered weakly
  absl::Duration drain_notice_;
  int port_ = 0;
  int metrics_port_ = -1;
  absl::Mutex drain_mu_;
  bool drained_ = false;
  std::atomic<bool> index_stop_{false};
  std::thread index_thread_;
  absl::Mutex probe_mu_;
  bool probe_stop_ ABSL_GUARDED_BY(probe_mu_) = false;
  std::thread probe_thread_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_COVPLAN_SERVER_H_
