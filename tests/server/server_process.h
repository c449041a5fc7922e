// Test-only: runs a real covplan-server process on loopback with a chosen
// store directory, learns its ports from its start-up log line (and waits
// for the store to be indexed), and stops it with SIGTERM (SIGKILL if it
// does not exit in time).
//
//   ServerProcess server;
//   ASSERT_TRUE(server.Start(store_dir, {"--threads=1"}).ok());
//   auto channel = grpc::CreateChannel(server.target(), grpc::InsecureChannelCredentials());
//   ASSERT_EQ(server.Stop(), 0);  // exit status
//
// Thread-safety: not thread-safe; one test thread owns it.
#ifndef COVPLAN_TESTS_SERVER_SERVER_PROCESS_H_
#define COVPLAN_TESTS_SERVER_SERVER_PROCESS_H_

#include <sys/types.h>

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/time/time.h"

namespace covplan::testing {

class ServerProcess {
 public:
  ServerProcess() = default;
  ~ServerProcess();  // SIGKILL if still running
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  // Starts `binary` (default: $COVPLAN_TEST_SERVER_BIN if set, else the
  // covplan-server built with the tests).
  absl::Status Start(const std::string& store_dir, const std::vector<std::string>& extra_args,
                     const std::string& binary = "");
  // SIGTERM, then waits up to `timeout`; returns the exit status, or -1 if
  // it had to be killed.
  int Stop(absl::Duration timeout = absl::Seconds(20));
  // Sends SIGTERM without waiting.
  void Terminate();
  // Waits for exit; -1 on timeout.
  int Wait(absl::Duration timeout);

  int port() const { return port_; }
  int metrics_port() const { return metrics_port_; }
  std::string target() const;
  std::string log() const;  // everything the server wrote to stderr
  pid_t pid() const { return pid_; }
  // When Start failed because the process exited: its exit status (or 128 +
  // signal); -1 otherwise.
  int start_exit_status() const { return start_exit_status_; }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  int metrics_port_ = 0;
  int start_exit_status_ = -1;
  std::string log_path_;
};

// The flags the process-level test fixtures start a server with (flags
// given after them win): no /metrics (its HTTP server takes ~2 s to stop),
// no drain notice, and the reply margin (--deadline_margin_ms, the service's
// default) scaled by kTimingSlowdown: a sanitized server needs longer to
// notice its stop and send, so a reply due at the deadline arrives in time.
std::vector<std::string> QuietServerFlags();

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_SERVER_PROCESS_H_
