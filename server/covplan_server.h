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

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/service.h"

namespace grpc {
class Server;
}
namespace prometheus {
class Collectable;
class Exposer;
}

namespace covplan {

struct ServerConfig {
  std::string address = "127.0.0.1";
  int port = 50051;                  // 0: pick a free port
  std::string metrics_address = "127.0.0.1";
  int metrics_port = 9464;           // 0: pick a free port; -1: no metrics endpoint
  std::string store_dir = "./covplan-data/maps";
  // "disk" (the embedded store in store_dir, default) or "postgres" (shared
  // by replicas; pg_conninfo is a libpq connection string).
  std::string map_store = "disk";
  std::string pg_conninfo;
  int max_message_bytes = 80 << 20;  // largest request accepted
  // On Drain, how long health reports NOT_SERVING (and new work is refused)
  // before the listener closes, so load balancers see it.
  absl::Duration drain_notice = absl::ZeroDuration();
  ServiceOptions service;
};

class CovplanServer {
 public:
  // Fails clearly when a port is taken or the store cannot be opened.
  static absl::StatusOr<std::unique_ptr<CovplanServer>> Start(const ServerConfig& config);
  ~CovplanServer();  // Drain(0)

  int port() const { return port_; }
  int metrics_port() const { return metrics_port_; }
  CoveragePlannerService& service() { return *service_; }

  // Reports NOT_SERVING and refuses new work (for the configured drain
  // notice), lets in-flight calls finish for up to `grace` in all (then
  // cancels them), and stops.
  void Drain(absl::Duration grace);

 private:
  CovplanServer() = default;

  std::unique_ptr<MapRepository> store_;
  std::unique_ptr<ServerMetrics> metrics_;
  std::unique_ptr<CoveragePlannerService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<prometheus::Exposer> exposer_;
  std::shared_ptr<prometheus::Collectable> process_metrics_;  // registered weakly
  absl::Duration drain_notice_;
  int port_ = 0;
  int metrics_port_ = -1;
  absl::Mutex drain_mu_;
  bool drained_ = false;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_COVPLAN_SERVER_H_
