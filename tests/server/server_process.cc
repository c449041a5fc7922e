#include "tests/server/server_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "server/service_options.h"
#include "tests/testing/timing.h"

namespace covplan::testing {
namespace {

// Value of `key=` in a log line, up to the next space.
std::string Field(const std::string& line, const std::string& key) {
  const size_t at = line.find(" " + key + "=");
  if (at == std::string::npos) return "";
  const size_t start = at + key.size() + 2;
  const size_t end = line.find(' ', start);
  return line.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

}  // namespace

ServerProcess::~ServerProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
}

absl::Status ServerProcess::Start(const std::string& store_dir,
                                  const std::vector<std::string>& extra_args,
                                  const std::string& binary) {
  // COVPLAN_TEST_SERVER_BIN runs the suite against another build (e.g. to
  // show that a test fails on the code before a fix).
  const char* override_bin = std::getenv("COVPLAN_TEST_SERVER_BIN");
  const std::string program = !binary.empty() ? binary
                              : (override_bin != nullptr && *override_bin != '\0')
                                  ? override_bin
                                  : COVPLAN_SERVER_BIN;
  log_path_ =
      absl::StrCat(store_dir, ".server.", ::getpid(), ".", absl::ToUnixMicros(absl::Now()), ".log");
  std::vector<std::string> args = {program,
                                   "--address=127.0.0.1",
                                   "--port=0",
                                   "--metrics_address=127.0.0.1",
                                   "--metrics_port=0",
                                   "--store_dir=" + store_dir};
  args.insert(args.end(), extra_args.begin(), extra_args.end());
  const int log_fd = ::open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) return absl::InternalError("cannot create the server log file");
  // Everything the child needs is prepared before fork: only
  // async-signal-safe calls may follow it in a multi-threaded process.
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_ = ::fork();
  if (pid_ < 0) return absl::InternalError("fork failed");
  if (pid_ == 0) {
    ::dup2(log_fd, STDERR_FILENO);
    ::dup2(log_fd, STDOUT_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(log_fd);
  // Wait (bounded) for the start-up line that names the ports.
  for (int i = 0; i < 300; ++i) {
    const std::string text = log();
    const size_t at = text.find("msg=\"covplan-server started\"");
    if (at != std::string::npos) {
      const std::string line = text.substr(at, text.find('\n', at) - at);
      const std::string address = Field(line, "address");
      const std::string port = address.substr(address.rfind(':') + 1);
      if (!absl::SimpleAtoi(port, &port_) ||
          !absl::SimpleAtoi(Field(line, "metrics_port"), &metrics_port_)) {
        return absl::InternalError(absl::StrCat("cannot parse start-up line: ", line));
      }
      // The store is indexed after the port opens; tests start once it is.
      for (int j = 0; j < 600 && log().find("msg=\"map store indexed\"") == std::string::npos;
           ++j) {
        absl::SleepFor(absl::Milliseconds(20));
      }
      return absl::OkStatus();
    }
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      start_exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return absl::InternalError(absl::StrCat("server exited during start-up: ", text));
    }
    absl::SleepFor(absl::Milliseconds(50));
  }
  return absl::DeadlineExceededError(absl::StrCat("server did not start: ", log()));
}

void ServerProcess::Terminate() {
  if (pid_ > 0) ::kill(pid_, SIGTERM);
}

int ServerProcess::Wait(absl::Duration timeout) {
  if (pid_ <= 0) return -1;
  const absl::Time end = absl::Now() + timeout;
  while (absl::Now() < end) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    absl::SleepFor(absl::Milliseconds(20));
  }
  return -1;
}

int ServerProcess::Stop(absl::Duration timeout) {
  Terminate();
  const int status = Wait(timeout);
  if (status == -1 && pid_ > 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  return status;
}

std::string ServerProcess::target() const { return absl::StrCat("127.0.0.1:", port_); }

std::string ServerProcess::log() const {
  std::ifstream in(log_path_);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> QuietServerFlags() {
  const double margin_ms = absl::ToDoubleMilliseconds(ServiceOptions().deadline_margin);
  return {"--metrics_port=-1", "--drain_notice_s=0",
          absl::StrCat("--deadline_margin_ms=", static_cast<int>(margin_ms * kTimingSlowdown))};
}

}  // namespace covplan::testing
