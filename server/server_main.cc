// covplan-server: the coverage planning gRPC service.
//
//   covplan-server --address=127.0.0.1 --port=50051 --metrics_port=9464
//                  --store_dir=./covplan-data/maps --threads=2
//
// SIGTERM / SIGINT: health goes NOT_SERVING, new work is refused, in-flight
// calls get --drain_grace_s to finish, then the process exits 0.
#include <signal.h>

#include <cstdio>
#include <cstdlib>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/covplan_server.h"
#include "server/log.h"

ABSL_FLAG(std::string, address, "127.0.0.1", "Address to listen on (0.0.0.0 for all)");
ABSL_FLAG(int, port, 50051, "gRPC port (0 picks a free one)");
ABSL_FLAG(std::string, metrics_address, "127.0.0.1", "Address of the /metrics endpoint");
ABSL_FLAG(int, metrics_port, 9464, "Prometheus /metrics port (0 picks, -1 disables)");
ABSL_FLAG(std::string, store_dir, "./covplan-data/maps", "Directory of the map registry");
ABSL_FLAG(std::string, map_store, "disk",
          "Map registry: disk (embedded, in --store_dir) or postgres (shared by replicas)");
ABSL_FLAG(std::string, pg_conninfo, "",
          "With --map_store=postgres: libpq connection string, e.g. \"host=/run/pg dbname=covplan\"");
ABSL_FLAG(int, threads, 2, "Worker threads for planning");
ABSL_FLAG(int, max_queue, 16, "Requests that may wait for a worker; beyond: RESOURCE_EXHAUSTED");
ABSL_FLAG(int64_t, cache_mb, 256, "Per-map artifact cache budget in MiB (grids, coverage areas, partitions, transitions)");
ABSL_FLAG(double, default_budget_s, 2.0, "Tour search budget for calls without a deadline");
ABSL_FLAG(int, deadline_margin_ms, 25, "Part of a call's deadline kept for sending the reply");
ABSL_FLAG(int, plan_ttl_s, 600, "How long plans stay addressable by plan_id");
ABSL_FLAG(int, max_retained_plans, 256, "Most plans kept for GetPlan");
ABSL_FLAG(int64_t, max_image_mb, 64, "Largest accepted map image, MiB");
ABSL_FLAG(int64_t, max_map_pixels, 64'000'000, "Largest accepted map, pixels");
ABSL_FLAG(int64_t, max_grid_cells, 4'000'000, "Largest accepted tool-width grid, cells");
ABSL_FLAG(int64_t, max_ranks, 1000,
          "Most coverage ranks per plan (the transition table grows with ranks^2)");
ABSL_FLAG(double, max_request_s, 120.0,
          "Calls without a deadline stop after this long with DEADLINE_EXCEEDED");
ABSL_FLAG(double, drain_grace_s, 10.0, "On SIGTERM, time in-flight calls get to finish");
ABSL_FLAG(double, drain_notice_s, 1.0,
          "On SIGTERM, time health reports NOT_SERVING before the port closes (within the grace)");

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage("coverage path planning gRPC service");
  // --help lists this file's flags (absl looks for a file named after the
  // binary by default and would show none).
  absl::FlagsUsageConfig usage;
  usage.contains_help_flags = [](absl::string_view path) {
    return absl::StrContains(path, "server/server_main.cc");
  };
  absl::SetFlagsUsageConfig(usage);
  absl::ParseCommandLine(argc, argv);

  // Block the signals in every thread; this one waits for them below.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  covplan::ServerConfig config;
  config.address = absl::GetFlag(FLAGS_address);
  config.port = absl::GetFlag(FLAGS_port);
  config.metrics_address = absl::GetFlag(FLAGS_metrics_address);
  config.metrics_port = absl::GetFlag(FLAGS_metrics_port);
  config.store_dir = absl::GetFlag(FLAGS_store_dir);
  config.map_store = absl::GetFlag(FLAGS_map_store);
  config.pg_conninfo = absl::GetFlag(FLAGS_pg_conninfo);
  config.drain_notice = absl::Seconds(absl::GetFlag(FLAGS_drain_notice_s));
  covplan::ServiceOptions& service = config.service;
  service.worker_threads = absl::GetFlag(FLAGS_threads);
  service.max_queue = absl::GetFlag(FLAGS_max_queue);
  service.cache_budget_bytes = static_cast<size_t>(absl::GetFlag(FLAGS_cache_mb)) << 20;
  service.default_budget_s = absl::GetFlag(FLAGS_default_budget_s);
  service.deadline_margin = absl::Milliseconds(absl::GetFlag(FLAGS_deadline_margin_ms));
  service.plan_ttl = absl::Seconds(absl::GetFlag(FLAGS_plan_ttl_s));
  service.max_retained_plans = static_cast<size_t>(std::max(0, absl::GetFlag(FLAGS_max_retained_plans)));
  service.limits.max_image_bytes = absl::GetFlag(FLAGS_max_image_mb) << 20;
  service.limits.max_map_pixels = absl::GetFlag(FLAGS_max_map_pixels);
  service.limits.max_grid_cells = absl::GetFlag(FLAGS_max_grid_cells);
  service.limits.max_ranks = absl::GetFlag(FLAGS_max_ranks);
  const double max_request_s = absl::GetFlag(FLAGS_max_request_s);
  if (!(max_request_s > 0)) {
    std::fprintf(stderr, "covplan-server: --max_request_s must be a positive number of seconds\n");
    return 1;
  }
  service.max_request_time = absl::Seconds(max_request_s);
  // Room for the image plus YAML and the rest of the request.
  config.max_message_bytes =
      static_cast<int>(std::min<int64_t>(service.limits.max_image_bytes + (4 << 20), INT32_MAX));

  absl::StatusOr<std::unique_ptr<covplan::CovplanServer>> server = covplan::CovplanServer::Start(config);
  if (!server.ok()) {
    std::fprintf(stderr, "covplan-server: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  int signal_number = 0;
  sigwait(&signals, &signal_number);
  covplan::LogLine("info", "signal received, shutting down",
                   {{"signal", absl::StrCat(signal_number)}});
  (*server)->Drain(absl::Seconds(absl::GetFlag(FLAGS_drain_grace_s)));
  return 0;
}
