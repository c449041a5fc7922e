#include "server/covplan_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server.h>
#include <grpcpp/server_builder.h>

#include <algorithm>
#include <exception>

#include "absl/strings/str_cat.h"
#include "prometheus/exposer.h"
#include "server/log.h"
#include "server/map_store.h"
#ifdef COVPLAN_HAVE_POSTGRES
#include "server/pg_map_store.h"
#endif
#include "server/process_metrics.h"

namespace covplan {
namespace {

absl::StatusOr<std::unique_ptr<MapRepository>> OpenMapStore(const ServerConfig& config) {
  if (config.map_store == "disk") {
    absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(config.store_dir);
    if (!store.ok()) return store.status();
    return std::unique_ptr<MapRepository>(std::move(*store));
  }
  if (config.map_store == "postgres") {
#ifdef COVPLAN_HAVE_POSTGRES
    absl::StatusOr<std::unique_ptr<PgMapStore>> store = PgMapStore::Open(config.pg_conninfo);
    if (!store.ok()) return store.status();
    return std::unique_ptr<MapRepository>(std::move(*store));
#else
    return absl::InvalidArgumentError(
        "--map_store=postgres: this covplan-server was built without libpq (install libpq-dev)");
#endif
  }
  return absl::InvalidArgumentError(
      absl::StrCat("--map_store must be disk or postgres, not \"", config.map_store, "\""));
}

}  // namespace

absl::StatusOr<std::unique_ptr<CovplanServer>> CovplanServer::Start(const ServerConfig& config) {
  if (absl::Status s = config.service.Validate(); !s.ok()) return s;
  std::unique_ptr<CovplanServer> server(new CovplanServer());
  server->drain_notice_ = config.drain_notice;
  absl::StatusOr<std::unique_ptr<MapRepository>> store = OpenMapStore(config);
  if (!store.ok()) return store.status();
  server->store_ = std::move(*store);
  std::vector<std::string> corrupted;
  server->store_->List(&corrupted);
  for (const std::string& id : corrupted) {
    LogLine("error", "corrupted map file in store, not served", {{"map_id", id}});
  }
  server->metrics_ = std::make_unique<ServerMetrics>();
  server->service_ = std::make_unique<CoveragePlannerService>(
      config.service, server->store_.get(), server->metrics_.get());

  if (config.metrics_port >= 0) {
    const std::string bind = absl::StrCat(config.metrics_address, ":", config.metrics_port);
    try {
      server->exposer_ = std::make_unique<prometheus::Exposer>(bind, /*num_threads=*/1);
    } catch (const std::exception& e) {
      return absl::UnavailableError(
          absl::StrCat("cannot serve /metrics on ", bind, " (port in use?): ", e.what()));
    }
    server->exposer_->RegisterCollectable(server->metrics_->registry());
    server->process_metrics_ = std::make_shared<ProcessMetrics>();
    server->exposer_->RegisterCollectable(server->process_metrics_);
    const std::vector<int> ports = server->exposer_->GetListeningPorts();
    server->metrics_port_ = ports.empty() ? config.metrics_port : ports.front();
  }

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  // gRPC 1.51 sets SO_REUSEPORT by default, which would let two servers
  // share a port silently; we want the second one to fail.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(config.max_message_bytes);
  builder.SetMaxSendMessageSize(config.max_message_bytes);
  const std::string address = absl::StrCat(config.address, ":", config.port);
  builder.AddListeningPort(address, grpc::InsecureServerCredentials(), &server->port_);
  builder.RegisterService(server->service_.get());
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || server->port_ == 0) {
    server->server_.reset();
    return absl::UnavailableError(
        absl::StrCat("cannot listen on ", address, " (port in use or bad address)"));
  }
  grpc::HealthCheckServiceInterface* health = server->server_->GetHealthCheckService();
  health->SetServingStatus(true);
  health->SetServingStatus(v1::CoveragePlanner::service_full_name(), true);
  LogLine("info", "covplan-server started",
          {{"address", absl::StrCat(config.address, ":", server->port_)},
           {"metrics_port", absl::StrCat(server->metrics_port_)},
           {"store_dir", config.store_dir},
           {"maps", absl::StrCat(server->store_->size())},
           {"workers", absl::StrCat(config.service.worker_threads)},
           {"queue", absl::StrCat(config.service.max_queue)}});
  return server;
}

void CovplanServer::Drain(absl::Duration grace) {
  absl::MutexLock lock(&drain_mu_);
  if (drained_) return;
  drained_ = true;
  if (server_ != nullptr) {
    server_->GetHealthCheckService()->SetServingStatus(false);
    service_->StartDraining();
    LogLine("info", "draining", {{"grace_ms", absl::StrCat(absl::ToInt64Milliseconds(grace))}});
    const absl::Time give_up = absl::Now() + grace;
    absl::SleepFor(std::min(drain_notice_, grace));
    // Waits for in-flight calls until the deadline, then cancels the rest;
    // their StopTokens fire and the workers finish them quickly.
    server_->Shutdown(absl::ToChronoTime(give_up));
    LogLine("info", "gRPC server shut down");
  }
  if (service_ != nullptr) service_->Shutdown();
  exposer_.reset();
  if (server_ != nullptr) {
    server_->Wait();
    LogLine("info", "covplan-server stopped");
  }
}

CovplanServer::~CovplanServer() {
  Drain(absl::ZeroDuration());
  server_.reset();   // before the service it dispatches to
  service_.reset();
}

}  // namespace covplan
