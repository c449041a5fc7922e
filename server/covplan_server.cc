#include "server/covplan_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server.h>
#include <grpcpp/server_builder.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "prometheus/exposer.h"
#include "server/log.h"
#include "server/malformed_request_interceptor.h"
#include "server/map_store.h"
#ifdef COVPLAN_HAVE_POSTGRES
#include "server/pg_map_store.h"
#endif
#include "server/process_metrics.h"
#include "server/transport_auth.h"

namespace covplan {
namespace {

// A file's modification time and size, "" when it cannot be read.
std::string FileStamp(const std::string& path) {
  if (path.empty()) return "";
  std::error_code ec;
  const auto time = std::filesystem::last_write_time(path, ec);
  if (ec) return "";
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return "";
  return absl::StrCat(time.time_since_epoch().count(), "/", size);
}

// Logs a reread of a token or quota file: how many entries it holds now, or
// why the previous ones stay in force (and returns that error).
absl::Status LogReload(const absl::StatusOr<size_t>& loaded, const char* failed, const char* done,
                       const char* unit) {
  if (!loaded.ok()) {
    LogLine("error", failed, {{"detail", std::string(loaded.status().message())}});
    return loaded.status();
  }
  LogLine("info", done, {{unit, absl::StrCat(*loaded)}});
  return absl::OkStatus();
}

// After the grace: how long cut-short solves get to reply, then how long
// gRPC gets to send what is written before it cancels the rest.
constexpr absl::Duration kDrainReplyBound = absl::Milliseconds(500);
constexpr absl::Duration kDrainFlushBound = absl::Milliseconds(200);

absl::StatusOr<std::string> ReadPem(const std::string& path, const char* flag) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().find("-----BEGIN ") == std::string::npos) {
    return absl::InvalidArgumentError(absl::StrCat(flag, " ", path, ": not a readable PEM file"));
  }
  return text.str();
}

bool IsLoopback(const std::string& address) {
  return address == "127.0.0.1" || address == "localhost" || address == "::1" || address == "[::1]";
}

// The listening port's credentials: TLS with --tls_cert, else plaintext.
// With `auth` (a token file), calls are checked by it at the transport on a
// TLS port and on a plaintext loopback port (gRPC's local credentials, which
// take a processor and accept loopback peers only); gRPC 1.51's insecure
// credentials take none, so a plaintext port beyond loopback checks tokens
// at the call gate alone.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> CredentialsFor(
    const ServerConfig& config, const std::shared_ptr<TransportAuth>& auth) {
  if (config.tls_cert_file.empty() != config.tls_key_file.empty()) {
    return absl::InvalidArgumentError("--tls_cert and --tls_key go together");
  }
  if (config.tls_cert_file.empty()) {
    if (!config.tls_client_ca_file.empty()) {
      return absl::InvalidArgumentError("--tls_client_ca needs --tls_cert and --tls_key");
    }
    if (auth == nullptr || !IsLoopback(config.address)) return grpc::InsecureServerCredentials();
    std::shared_ptr<grpc::ServerCredentials> local =
        grpc::experimental::LocalServerCredentials(LOCAL_TCP);
    local->SetAuthMetadataProcessor(auth);
    return local;
  }
  grpc::SslServerCredentialsOptions options;
  grpc::SslServerCredentialsOptions::PemKeyCertPair pair;
  absl::StatusOr<std::string> cert = ReadPem(config.tls_cert_file, "--tls_cert");
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key = ReadPem(config.tls_key_file, "--tls_key");
  if (!key.ok()) return key.status();
  pair.cert_chain = *cert;
  pair.private_key = *key;
  options.pem_key_cert_pairs.push_back(pair);
  if (!config.tls_client_ca_file.empty()) {
    absl::StatusOr<std::string> ca = ReadPem(config.tls_client_ca_file, "--tls_client_ca");
    if (!ca.ok()) return ca.status();
    options.pem_root_certs = *ca;
    options.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  std::shared_ptr<grpc::ServerCredentials> tls = grpc::SslServerCredentials(options);
  if (auth != nullptr) tls->SetAuthMetadataProcessor(auth);
  return tls;
}

absl::StatusOr<std::unique_ptr<MapRepository>> OpenMapStore(const ServerConfig& config) {
  if (config.map_store == "disk") {
    absl::StatusOr<std::unique_ptr<MapStore>> store =
        MapStore::OpenLocked(config.store_dir, /*index=*/!config.index_in_background);
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
  if (config.http_port >= 0 && !config.tls_cert_file.empty()) {
    return absl::InvalidArgumentError(
        "--http_port: the JSON API does not serve TLS yet; with --tls_cert set, leave it off and "
        "call the gRPC port");
  }
  std::unique_ptr<CovplanServer> server(new CovplanServer());
  server->drain_notice_ = config.drain_notice;
  absl::StatusOr<std::unique_ptr<MapRepository>> store = OpenMapStore(config);
  if (!store.ok()) return store.status();
  server->store_ = std::move(*store);
  if (!config.index_in_background) server->LogIndexed(absl::ZeroDuration());
  if (!config.token_file.empty()) {
    absl::StatusOr<std::unique_ptr<TenantTokens>> tokens = TenantTokens::Load(config.token_file);
    if (!tokens.ok()) return tokens.status();
    server->tokens_ = std::move(*tokens);
    if (config.tls_cert_file.empty() && !IsLoopback(config.address)) {
      LogLine("warn",
              "bearer tokens on a plaintext port beyond loopback travel in the clear and are "
              "checked at the call gate, not the transport (gRPC's plaintext credentials take no "
              "auth processor); use --tls_cert",
              {{"address", config.address}});
    }
  }
  absl::StatusOr<std::unique_ptr<TenantQuotas>> quotas =
      TenantQuotas::Load(config.service.tenant_quota, config.tenant_quota_file);
  if (!quotas.ok()) return quotas.status();
  server->quotas_ = std::move(*quotas);
  server->token_file_ = config.token_file;
  server->quota_file_ = config.tenant_quota_file;
  {
    absl::MutexLock lock(&server->reload_mu_);
    server->token_stamp_ = FileStamp(config.token_file);
    server->quota_stamp_ = FileStamp(config.tenant_quota_file);
  }
  if (!config.tenant_quota_file.empty() && config.token_file.empty()) {
    LogLine("warn",
            "--tenant_quota_file without --token_file: every caller is one tenant, "
            "which gets the --tenant_max_* defaults; the file's lines never apply");
  }
  server->metrics_ = std::make_unique<ServerMetrics>();
  server->service_ = std::make_unique<CoveragePlannerService>(
      config.service, server->store_.get(), server->metrics_.get(), server->tokens_.get(),
      server->quotas_.get());

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
  // Clients of long Drive streams over flaky links (the Python client) send
  // keepalive pings every 20 s during a call to notice a dead link; gRPC's
  // default (a ping per 5 minutes, two strikes) would answer them with GOAWAY.
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 10000);
  builder.SetMaxReceiveMessageSize(config.max_message_bytes);
  builder.SetMaxSendMessageSize(config.max_message_bytes);
  const std::string address = absl::StrCat(config.address, ":", config.port);
  std::shared_ptr<TransportAuth> auth =
      server->tokens_ == nullptr
          ? nullptr
          : std::make_shared<TransportAuth>(server->tokens_.get(), server->metrics_.get());
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      CredentialsFor(config, auth);
  if (!credentials.ok()) return credentials.status();
  builder.AddListeningPort(address, *credentials, &server->port_);
  builder.RegisterService(server->service_.get());
  builder.experimental().SetInterceptorCreators(
      MalformedRequestInterceptors(server->metrics_.get()));
  server->server_ = builder.BuildAndStart();
  if (server->server_ == nullptr || server->port_ == 0) {
    server->server_.reset();
    return absl::UnavailableError(
        absl::StrCat("cannot listen on ", address, " (port in use or bad address)"));
  }
  if (config.http_port >= 0) {
    HttpGatewayOptions http;
    http.address = config.http_address;
    http.port = config.http_port;
    // bytes fields travel as base64 in JSON: 4/3 of gRPC's limit, and some.
    http.max_body_bytes = int64_t{config.max_message_bytes} * 4 / 3 + (1 << 20);
    http.request_timeout_ms = config.http_request_timeout_ms;
    http.tokens = server->tokens_.get();
    http.metrics = server->metrics_.get();
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(config.max_message_bytes);
    args.SetMaxSendMessageSize(config.max_message_bytes);
    absl::StatusOr<std::unique_ptr<HttpGateway>> gateway =
        HttpGateway::Start(http, server->server_->InProcessChannel(args), server->service_->live());
    if (!gateway.ok()) return gateway.status();  // ~CovplanServer stops gRPC
    server->http_ = std::move(*gateway);
  }
  grpc::HealthCheckServiceInterface* health = server->server_->GetHealthCheckService();
  const bool indexed = !server->store_->loading();
  health->SetServingStatus(indexed);
  health->SetServingStatus(v1::CoveragePlanner::service_full_name(), indexed);
  const bool writable = server->store_->ProbeWritable().ok();
  health->SetServingStatus(kStoreHealthService, writable);
  server->metrics_->store_writable().Set(writable ? 1 : 0);
  if (!writable) LogLine("error", "map store is not writable; PutMap and DeleteMap will fail");
  server->probe_thread_ =
      std::thread(&CovplanServer::ProbeStoreLoop, server.get(), config.store_probe_interval);
  if (!indexed) {
    server->index_thread_ = std::thread([raw = server.get()] {
      const absl::Time start = absl::Now();
      const absl::Status loaded = raw->store_->LoadIndex(&raw->index_stop_);
      if (!loaded.ok()) {
        LogLine(raw->index_stop_.load() ? "info" : "error", "map store not indexed",
                {{"detail", std::string(loaded.message())}});
        return;
      }
      raw->LogIndexed(absl::Now() - start);
      raw->metrics_->maps_stored().Set(static_cast<double>(raw->store_->size()));
      if (!raw->service_->draining()) {
        grpc::HealthCheckServiceInterface* health = raw->server_->GetHealthCheckService();
        health->SetServingStatus(true);
        health->SetServingStatus(v1::CoveragePlanner::service_full_name(), true);
      }
    });
  }
  LogLine("info", "covplan-server started",
          {{"address", absl::StrCat(config.address, ":", server->port_)},
           {"metrics_port", absl::StrCat(server->metrics_port_)},
           {"http_port", absl::StrCat(server->http_port())},
           {"store_dir", config.store_dir},
           {"maps", absl::StrCat(server->store_->size())},
           {"workers", absl::StrCat(config.service.worker_threads)},
           {"tokens", server->tokens_ == nullptr ? "off" : absl::StrCat(server->tokens_->size())},
           {"queue", absl::StrCat(config.service.max_queue)}});
  return server;
}

absl::Status CovplanServer::ReloadTokens() {
  absl::MutexLock lock(&reload_mu_);
  return ReloadTokensLocked();
}

absl::Status CovplanServer::ReloadQuotas() {
  absl::MutexLock lock(&reload_mu_);
  return ReloadQuotasLocked();
}

absl::Status CovplanServer::ReloadTokensLocked() {
  if (tokens_ == nullptr) return absl::OkStatus();
  token_stamp_ = FileStamp(token_file_);
  return LogReload(tokens_->Reload(), "token file not reloaded; the previous tokens stay in force",
                   "token file reloaded", "tokens");
}

absl::Status CovplanServer::ReloadQuotasLocked() {
  if (!quotas_->has_file()) return absl::OkStatus();
  quota_stamp_ = FileStamp(quota_file_);
  return LogReload(quotas_->Reload(),
                   "tenant quota file not reloaded; the previous quotas stay in force",
                   "tenant quotas reloaded", "tenants");
}

void CovplanServer::ReloadChangedFiles() {
  absl::MutexLock lock(&reload_mu_);
  if (!token_file_.empty() && tokens_ != nullptr && FileStamp(token_file_) != token_stamp_) {
    LogLine("info", "token file changed on disk; rereading it");
    (void)ReloadTokensLocked();  // logs its outcome
  }
  if (!quota_file_.empty() && FileStamp(quota_file_) != quota_stamp_) {
    LogLine("info", "tenant quota file changed on disk; rereading it");
    (void)ReloadQuotasLocked();
  }
}

void CovplanServer::LogIndexed(absl::Duration took) {
  std::vector<std::string> corrupted;
  store_->List(&corrupted);
  for (const std::string& id : corrupted) {
    LogLine("error", "corrupted map file in store, not served", {{"map_id", id}});
  }
  LogLine("info", "map store indexed",
          {{"maps", absl::StrCat(store_->size())},
           {"corrupted", absl::StrCat(corrupted.size())},
           {"ms", absl::StrCat(absl::ToInt64Milliseconds(took))}});
}

void CovplanServer::ProbeStoreLoop(absl::Duration interval) {
  bool was_writable = store_->writable();
  absl::MutexLock lock(&probe_mu_);
  while (!probe_mu_.AwaitWithTimeout(absl::Condition(&probe_stop_), interval)) {
    probe_mu_.Unlock();
    ReloadChangedFiles();
    const absl::Status probe = store_->ProbeWritable();
    // A write that failed since the last probe counts too.
    const bool writable = probe.ok() && store_->writable();
    if (writable != was_writable) {
      LogLine(writable ? "info" : "error",
              writable ? "map store writable again" : "map store is not writable",
              {{"detail", probe.ok() ? "" : std::string(probe.message())}});
      server_->GetHealthCheckService()->SetServingStatus(kStoreHealthService, writable);
      metrics_->store_writable().Set(writable ? 1 : 0);
      was_writable = writable;
    }
    probe_mu_.Lock();
  }
}

void CovplanServer::Drain(absl::Duration grace) {
  absl::MutexLock lock(&drain_mu_);
  if (drained_) return;
  drained_ = true;
  {
    absl::MutexLock probe_lock(&probe_mu_);
    probe_stop_ = true;
  }
  if (probe_thread_.joinable()) probe_thread_.join();
  index_stop_.store(true);
  if (index_thread_.joinable()) index_thread_.join();
  const absl::Time start = absl::Now();
  const absl::Time give_up = start + grace;
  if (server_ != nullptr) {
    server_->GetHealthCheckService()->SetServingStatus(false);
    service_->StartDraining();
    LogLine("info", "draining", {{"grace_ms", absl::StrCat(absl::ToInt64Milliseconds(grace))}});
    absl::SleepFor(std::min(drain_notice_, grace));
    // Our own calls decide how long the grace lasts, not gRPC's count of
    // open streams: a health Watch stream or an idle connection never ends
    // by itself and would hold Shutdown for the whole deadline.
    while (service_->active_calls() > 0 && absl::Now() < give_up)
      absl::SleepFor(absl::Milliseconds(10));
    if (service_->active_calls() > 0) {
      // Grace over: running solves stop and answer with their best plan.
      service_->CutShortInFlight();
      const absl::Time replies_by = absl::Now() + kDrainReplyBound;
      while (service_->active_calls() > 0 && absl::Now() < replies_by) {
        absl::SleepFor(absl::Milliseconds(5));
      }
    }
    // Cancels what is left (streams, calls that did not reply in time), after
    // a moment for the replies just sent to leave. The JSON API starts no
    // call from here on.
    if (http_ != nullptr) http_->StopCalls();
    server_->Shutdown(absl::ToChronoTime(absl::Now() + kDrainFlushBound));
    LogLine("info", "gRPC server shut down",
            {{"ms", absl::StrCat(absl::ToInt64Milliseconds(absl::Now() - start))}});
  }
  // After the gRPC server: the JSON API's calls in flight are its calls,
  // answered or cancelled by now, so the HTTP handlers return.
  http_.reset();
  if (service_ != nullptr) service_->Shutdown();
  exposer_.reset();
  if (server_ != nullptr) {
    server_->Wait();
    LogLine("info", "covplan-server stopped",
            {{"ms", absl::StrCat(absl::ToInt64Milliseconds(absl::Now() - start))}});
  }
}

CovplanServer::~CovplanServer() {
  Drain(absl::ZeroDuration());
  server_.reset();  // before the service it dispatches to
  service_.reset();
}

}  // namespace covplan
