// covplan-server: the coverage planning gRPC service.
//
//   covplan-server --address=127.0.0.1 --port=50051 --metrics_port=9464
//                  --store_dir=./covplan-data/maps --threads=2
//
// SIGHUP: rereads --token_file and --tenant_quota_file (a bad file keeps the
// previous table).
// SIGTERM / SIGINT: health goes NOT_SERVING, new work is refused, in-flight
// calls get --drain_grace_s to finish (then running plans answer with their
// best so far), and the process exits 0 within the grace plus 1.5 s. A signal
// during start-up (e.g. while the store is indexed) exits at once.
// Every flag is range-checked first; a bad value exits 2 with a message
// naming the flag (absl's own parse errors, such as an unknown flag or a
// non-number, exit 1).
#include <malloc.h>
#include <signal.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <type_traits>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "server/covplan_server.h"
#include "server/log.h"

ABSL_FLAG(std::string, address, "127.0.0.1", "Address to listen on (0.0.0.0 for all)");
ABSL_FLAG(int, port, 50051, "gRPC port (0 picks a free one)");
ABSL_FLAG(std::string, metrics_address, "127.0.0.1", "Address of the /metrics endpoint");
ABSL_FLAG(int, metrics_port, 9464, "Prometheus /metrics port (0 picks, -1 disables)");
ABSL_FLAG(std::string, http_address, "127.0.0.1", "Address of the JSON API (HTTP)");
ABSL_FLAG(int, http_port, -1,
          "JSON API port: POST /v1/<Method> in protobuf's JSON mapping (0 picks, -1 disables)");
ABSL_FLAG(std::string, store_dir, "./covplan-data/maps", "Directory of the map registry");
ABSL_FLAG(std::string, map_store, "disk",
          "Map registry: disk (embedded, in --store_dir) or postgres (shared by replicas)");
ABSL_FLAG(
    std::string, pg_conninfo, "",
    "With --map_store=postgres: libpq connection string, e.g. \"host=/run/pg dbname=covplan\"");
ABSL_FLAG(int, threads, 2, "Worker threads for planning");
ABSL_FLAG(int, max_queue, 16, "Requests that may wait for a worker; beyond: RESOURCE_EXHAUSTED");
ABSL_FLAG(
    bool, plan_memory, true,
    "Remember plans within the --cache_mb budget: an identical Plan request is answered at once, "
    "one differing only in start/end pose or seed searches from the remembered tour; false: every "
    "request searches from scratch");
ABSL_FLAG(int64_t, cache_mb, 256,
          "Per-map artifact cache budget in MiB (grids, coverage areas, partitions, transitions)");
ABSL_FLAG(double, default_budget_s, covplan::CommonOptions::kDefaultTimeLimitS,
          "Tour search budget for calls without a deadline");
ABSL_FLAG(int, deadline_margin_ms, 25, "Part of a call's deadline kept for sending the reply");
ABSL_FLAG(int, plan_ttl_s, 600, "How long plans stay addressable by plan_id");
ABSL_FLAG(int, max_retained_plans, 256, "Most plans kept for GetPlan");
ABSL_FLAG(int64_t, max_image_mb, 64, "Largest accepted map image, MiB");
ABSL_FLAG(int64_t, max_map_pixels, 64'000'000, "Largest accepted map, pixels");
ABSL_FLAG(int64_t, max_grid_cells, 4'000'000, "Largest accepted tool-width grid, cells");
ABSL_FLAG(int64_t, max_ranks, 100000,
          "Hard cap on coverage ranks per plan (memory is bounded by --max_transition_mb)");
ABSL_FLAG(int64_t, max_transition_mb, 1024,
          "Memory budget of one plan's transitions, MiB (OARP all-pairs table or sparse candidate "
          "graph; boustrophedon table); above it: RESOURCE_EXHAUSTED");
ABSL_FLAG(
    int64_t, dense_transition_mb, 4,
    "OARP uses the exact all-pairs transition table and dense GTSP while they fit in this many "
    "MiB (about 100 ranks at the default), the sparse candidate graph above");
ABSL_FLAG(double, max_request_s, 120.0,
          "Calls without a deadline stop after this long with DEADLINE_EXCEEDED");
ABSL_FLAG(double, drain_grace_s, 10.0, "On SIGTERM, time in-flight calls get to finish");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM certificate chain for TLS on the gRPC port (with --tls_key); empty = plaintext");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(
    std::string, tls_client_ca, "",
    "PEM CA that client certificates must chain to (mutual TLS); empty = no client certificates");
ABSL_FLAG(std::string, token_file, "",
          "File of \"<sha256 hex of a bearer token> <tenant>\" lines; every call then needs "
          "\"authorization: Bearer <token>\" and sees only its tenant's maps and plans (health and "
          "reflection stay open). Reread on SIGHUP. Empty = no tokens");
ABSL_FLAG(int, tenant_max_solves, 0,
          "Solves one tenant may run at once (0 = no limit); its others wait while other "
          "tenants' run");
ABSL_FLAG(int, tenant_max_queued, 0,
          "Solves one tenant may have waiting beyond those (0 = no limit but --max_queue); "
          "beyond: RESOURCE_EXHAUSTED naming the quota");
ABSL_FLAG(int64_t, tenant_max_maps, 0, "Maps one tenant may store (0 = no limit)");
ABSL_FLAG(std::string, tenant_quota_file, "",
          "Per-tenant overrides, lines of \"<tenant> max_solves=N max_queued=N max_maps=N\" "
          "(any of them). Reread on SIGHUP. Empty = the --tenant_max_* flags for all");
ABSL_FLAG(int, max_sessions, 64, "Drive sessions open at once; beyond: RESOURCE_EXHAUSTED");
ABSL_FLAG(double, session_idle_s, 120.0,
          "A Drive session without a message for this long ends with DEADLINE_EXCEEDED");
ABSL_FLAG(int, max_live_streams, 4,
          "Live event streams (GET /v1/events) open at once (<= 32 of the 48 HTTP threads)");
ABSL_FLAG(std::string, replica, "",
          "This replica's name among replicas sharing one --map_store (at most 32 of [a-z0-9_]): "
          "what it learns is stored under it");
ABSL_FLAG(double, drain_notice_s, 1.0,
          "On SIGTERM, time health reports NOT_SERVING before the port closes (within the grace)");

namespace {

// How far past --drain_grace_s the process may run before it exits anyway.
constexpr absl::Duration kDrainOverrun = absl::Milliseconds(1500);

// The range every numeric flag must lie in, checked before anything starts.
template <typename T>
void CheckRange(const char* name, T value, T lo, T hi, std::vector<std::string>* errors) {
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value) || value < lo || value > hi) {
      errors->push_back(
          absl::StrCat("--", name, "=", value, ": must be a number in [", lo, ", ", hi, "]"));
    }
  } else if (value < lo || value > hi) {
    errors->push_back(
        absl::StrCat("--", name, "=", value, ": must be an integer in [", lo, ", ", hi, "]"));
  }
}

std::vector<std::string> ValidateFlags() {
  std::vector<std::string> errors;
  if (absl::GetFlag(FLAGS_address).empty()) errors.push_back("--address: must not be empty");
  if (absl::GetFlag(FLAGS_metrics_address).empty())
    errors.push_back("--metrics_address: must not be empty");
  if (absl::GetFlag(FLAGS_store_dir).empty()) errors.push_back("--store_dir: must not be empty");
  CheckRange("port", absl::GetFlag(FLAGS_port), 0, 65535, &errors);
  CheckRange("metrics_port", absl::GetFlag(FLAGS_metrics_port), -1, 65535, &errors);
  CheckRange("http_port", absl::GetFlag(FLAGS_http_port), -1, 65535, &errors);
  if (absl::GetFlag(FLAGS_http_address).empty())
    errors.push_back("--http_address: must not be empty");
  CheckRange("threads", absl::GetFlag(FLAGS_threads), 1, 256, &errors);
  CheckRange("max_queue", absl::GetFlag(FLAGS_max_queue), 0, 100000, &errors);
  CheckRange<int64_t>("cache_mb", absl::GetFlag(FLAGS_cache_mb), 1, 1 << 20, &errors);
  CheckRange("default_budget_s", absl::GetFlag(FLAGS_default_budget_s), 1e-3, 3600.0, &errors);
  CheckRange("deadline_margin_ms", absl::GetFlag(FLAGS_deadline_margin_ms), 0, 60000, &errors);
  CheckRange("plan_ttl_s", absl::GetFlag(FLAGS_plan_ttl_s), 1, 30 * 24 * 3600, &errors);
  CheckRange("max_retained_plans", absl::GetFlag(FLAGS_max_retained_plans), 1, 1000000, &errors);
  // The largest gRPC message is the image plus 4 MiB and must fit an int.
  CheckRange<int64_t>("max_image_mb", absl::GetFlag(FLAGS_max_image_mb), 1, 2000, &errors);
  CheckRange<int64_t>("max_map_pixels", absl::GetFlag(FLAGS_max_map_pixels), 1, int64_t{1} << 36,
                      &errors);
  CheckRange<int64_t>("max_grid_cells", absl::GetFlag(FLAGS_max_grid_cells), 1, int64_t{1} << 32,
                      &errors);
  CheckRange<int64_t>("max_ranks", absl::GetFlag(FLAGS_max_ranks), 1, 100000, &errors);
  CheckRange<int64_t>("max_transition_mb", absl::GetFlag(FLAGS_max_transition_mb), 1, 1 << 20,
                      &errors);
  CheckRange<int64_t>("dense_transition_mb", absl::GetFlag(FLAGS_dense_transition_mb), 0, 1 << 20,
                      &errors);
  CheckRange("max_request_s", absl::GetFlag(FLAGS_max_request_s), 1e-3, 24 * 3600.0, &errors);
  CheckRange("drain_grace_s", absl::GetFlag(FLAGS_drain_grace_s), 0.0, 3600.0, &errors);
  CheckRange("drain_notice_s", absl::GetFlag(FLAGS_drain_notice_s), 0.0, 3600.0, &errors);
  CheckRange("max_sessions", absl::GetFlag(FLAGS_max_sessions), 1, 100000, &errors);
  CheckRange("tenant_max_solves", absl::GetFlag(FLAGS_tenant_max_solves), 0, 100000, &errors);
  CheckRange("tenant_max_queued", absl::GetFlag(FLAGS_tenant_max_queued), 0, 100000, &errors);
  CheckRange<int64_t>("tenant_max_maps", absl::GetFlag(FLAGS_tenant_max_maps), 0, int64_t{1} << 40,
                      &errors);
  CheckRange("session_idle_s", absl::GetFlag(FLAGS_session_idle_s), 0.1, 24 * 3600.0, &errors);
  CheckRange("max_live_streams", absl::GetFlag(FLAGS_max_live_streams), 1, 32, &errors);
  {
    covplan::ServiceOptions replica;
    replica.replica = absl::GetFlag(FLAGS_replica);
    if (!replica.Validate().ok()) errors.push_back("--replica: at most 32 of [a-z0-9_]");
  }
  if (absl::GetFlag(FLAGS_tls_cert).empty() != absl::GetFlag(FLAGS_tls_key).empty()) {
    errors.push_back("--tls_cert and --tls_key: give both or neither");
  }
  if (!absl::GetFlag(FLAGS_tls_client_ca).empty() && absl::GetFlag(FLAGS_tls_cert).empty()) {
    errors.push_back("--tls_client_ca: needs --tls_cert and --tls_key");
  }
  return errors;
}

// The server's configuration from the (validated) flags.
covplan::ServerConfig ConfigFromFlags() {
  covplan::ServerConfig config;
  config.address = absl::GetFlag(FLAGS_address);
  config.port = absl::GetFlag(FLAGS_port);
  config.metrics_address = absl::GetFlag(FLAGS_metrics_address);
  config.metrics_port = absl::GetFlag(FLAGS_metrics_port);
  config.http_address = absl::GetFlag(FLAGS_http_address);
  config.http_port = absl::GetFlag(FLAGS_http_port);
  config.store_dir = absl::GetFlag(FLAGS_store_dir);
  config.map_store = absl::GetFlag(FLAGS_map_store);
  config.pg_conninfo = absl::GetFlag(FLAGS_pg_conninfo);
  config.drain_notice = absl::Seconds(absl::GetFlag(FLAGS_drain_notice_s));
  config.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  config.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  config.tls_client_ca_file = absl::GetFlag(FLAGS_tls_client_ca);
  config.token_file = absl::GetFlag(FLAGS_token_file);
  config.tenant_quota_file = absl::GetFlag(FLAGS_tenant_quota_file);
  // The port opens at once; health says NOT_SERVING until the store is indexed.
  config.index_in_background = true;
  covplan::ServiceOptions& service = config.service;
  service.worker_threads = absl::GetFlag(FLAGS_threads);
  service.max_queue = absl::GetFlag(FLAGS_max_queue);
  service.cache_budget_bytes = static_cast<size_t>(absl::GetFlag(FLAGS_cache_mb)) << 20;
  service.limits.plan_memory = absl::GetFlag(FLAGS_plan_memory);
  service.default_budget_s = absl::GetFlag(FLAGS_default_budget_s);
  service.deadline_margin = absl::Milliseconds(absl::GetFlag(FLAGS_deadline_margin_ms));
  service.plan_ttl = absl::Seconds(absl::GetFlag(FLAGS_plan_ttl_s));
  service.max_retained_plans = static_cast<size_t>(absl::GetFlag(FLAGS_max_retained_plans));
  service.limits.max_image_bytes = absl::GetFlag(FLAGS_max_image_mb) << 20;
  service.limits.max_map_pixels = absl::GetFlag(FLAGS_max_map_pixels);
  service.limits.max_grid_cells = absl::GetFlag(FLAGS_max_grid_cells);
  service.limits.max_ranks = absl::GetFlag(FLAGS_max_ranks);
  service.limits.max_transition_bytes = absl::GetFlag(FLAGS_max_transition_mb) << 20;
  service.limits.dense_transition_bytes = absl::GetFlag(FLAGS_dense_transition_mb) << 20;
  service.max_request_time = absl::Seconds(absl::GetFlag(FLAGS_max_request_s));
  service.tenant_quota.max_solves = absl::GetFlag(FLAGS_tenant_max_solves);
  service.tenant_quota.max_queued = absl::GetFlag(FLAGS_tenant_max_queued);
  service.tenant_quota.max_maps = absl::GetFlag(FLAGS_tenant_max_maps);
  service.max_sessions = absl::GetFlag(FLAGS_max_sessions);
  service.session_idle = absl::Seconds(absl::GetFlag(FLAGS_session_idle_s));
  service.max_live_streams = absl::GetFlag(FLAGS_max_live_streams);
  service.replica = absl::GetFlag(FLAGS_replica);
  // Room for the image plus YAML and the rest of the request.
  config.max_message_bytes =
      static_cast<int>(std::min<int64_t>(service.limits.max_image_bytes + (4 << 20), INT32_MAX));
  return config;
}

}  // namespace

int main(int argc, char** argv) {
  // Debian's abseil is built without NDEBUG, so every absl::Mutex would keep
  // a lock-order graph for deadlock detection: about 5 % of the server's CPU
  // on repeated cache hits (perf, docs/benchmarks.md §12). The in-process
  // tests keep it on; the binaries turn it off.
  absl::SetMutexDeadlockDetectionMode(absl::OnDeadlockCycle::kIgnore);
  // Block the signals in every thread before any is created; one thread
  // waits for them from here on, so SIGTERM works during start-up too.
  static sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // 0 until a signal arrives; -1 once the server runs (the main thread then
  // owns the drain).
  static std::atomic<int> received{0};
  static std::atomic<bool> started{false};
  static absl::Mutex signal_mu;
  // The running server, for SIGHUP (null before start and once draining).
  static covplan::CovplanServer* running = nullptr;  // guarded by signal_mu
  std::thread([] {
    int signal_number = 0;
    while (true) {
      sigwait(&signals, &signal_number);
      if (signal_number != SIGHUP) break;
      absl::MutexLock lock(&signal_mu);
      if (running == nullptr) {
        covplan::LogLine("info", "SIGHUP ignored: server not running");
      } else {
        (void)running->ReloadTokens();  // logs its outcome
        (void)running->ReloadQuotas();
      }
    }
    absl::MutexLock lock(&signal_mu);
    received.store(signal_number);
    if (!started.load()) {
      // Nothing to drain yet: start-up only reads the store.
      covplan::LogLine("info", "signal during start-up, exiting",
                       {{"signal", absl::StrCat(signal_number)}});
      std::fflush(stderr);
      std::_Exit(0);
    }
  }).detach();

  absl::SetProgramUsageMessage("coverage path planning gRPC service");
  // --help lists this file's flags (absl looks for a file named after the
  // binary by default and would show none).
  absl::FlagsUsageConfig usage;
  usage.contains_help_flags = [](absl::string_view path) {
    return absl::StrContains(path, "server/server_main.cc");
  };
  absl::SetFlagsUsageConfig(usage);
  const std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  std::vector<std::string> errors = ValidateFlags();
  for (size_t i = 1; i < positional.size(); ++i) {
    errors.push_back(absl::StrCat("unexpected argument '", std::string(positional[i]).substr(0, 64),
                                  "' (flags are --name=value)"));
  }
  if (!errors.empty()) {
    for (const std::string& e : errors) std::fprintf(stderr, "covplan-server: %s\n", e.c_str());
    std::fprintf(stderr, "covplan-server: see --help\n");
    return 2;
  }

  // One glibc arena per worker (plus the I/O and gRPC threads' few) instead
  // of up to 8 per core: each arena keeps its own high-water mark.
  mallopt(M_ARENA_MAX, absl::GetFlag(FLAGS_threads) + 4);

  const covplan::ServerConfig config = ConfigFromFlags();
  absl::StatusOr<std::unique_ptr<covplan::CovplanServer>> server =
      covplan::CovplanServer::Start(config);
  if (!server.ok()) {
    std::fprintf(stderr, "covplan-server: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  {
    absl::MutexLock lock(&signal_mu);
    started.store(true);
    running = server->get();
  }
  // Wait for the signal thread to record a signal.
  {
    absl::MutexLock lock(&signal_mu);
    signal_mu.Await(absl::Condition(
        +[](std::atomic<int>* r) { return r->load() != 0; }, &received));
  }
  {
    absl::MutexLock lock(&signal_mu);
    running = nullptr;  // no reload while the server drains and is destroyed
  }
  covplan::LogLine("info", "signal received, shutting down",
                   {{"signal", absl::StrCat(received.load())}});
  const absl::Duration grace = absl::Seconds(absl::GetFlag(FLAGS_drain_grace_s));
  // The drain is bounded by our own timing; should gRPC's transport
  // teardown (or the /metrics server's) still hang, exit anyway.
  std::thread([grace] {
    absl::SleepFor(grace + kDrainOverrun);
    covplan::LogLine(
        "warn", "drain overran its bound; exiting",
        {{"bound_ms", absl::StrCat(absl::ToInt64Milliseconds(grace + kDrainOverrun))}});
    std::fflush(stderr);
    std::_Exit(0);
  }).detach();
  (*server)->Drain(grace);
  return 0;
}
