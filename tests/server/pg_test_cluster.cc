#include "tests/server/pg_test_cluster.h"

#include <pwd.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "absl/strings/str_cat.h"

namespace covplan::testing {
namespace {

// initdb is not on PATH on Debian: look in the versioned directories.
std::string FindBinDir() {
  if (const char* env = std::getenv("PG_BIN"); env != nullptr && *env != '\0') {
    const std::string bin = env;
    return std::filesystem::exists(bin + "/initdb") ? bin : "";
  }
  std::error_code ec;
  std::string best;
  for (const auto& entry : std::filesystem::directory_iterator("/usr/lib/postgresql", ec)) {
    const std::string bin = entry.path().string() + "/bin";
    if (std::filesystem::exists(bin + "/initdb") && std::filesystem::exists(bin + "/pg_ctl") &&
        bin > best) {
      best = bin;
    }
  }
  return best;
}

}  // namespace

std::unique_ptr<PgTestCluster> PgTestCluster::Start(std::string* why) {
  std::unique_ptr<PgTestCluster> pg(new PgTestCluster());
  pg->bin_ = FindBinDir();
  if (pg->bin_.empty()) {
    *why =
        "no PostgreSQL server binaries (initdb, pg_ctl) under /usr/lib/postgresql; "
        "apt-get install postgresql to run these tests";
    return nullptr;
  }
  char pattern[] = "/tmp/covplan_pg_XXXXXX";
  if (mkdtemp(pattern) == nullptr) {
    *why = "cannot create a temp dir";
    return nullptr;
  }
  pg->dir_ = pattern;
  if (geteuid() == 0) {
    const passwd* user = getpwnam("postgres");
    if (user == nullptr) {
      *why = "running as root and there is no postgres user to run the server as";
      return nullptr;
    }
    if (chown(pg->dir_.c_str(), user->pw_uid, user->pw_gid) != 0) {
      *why = "cannot chown the temp dir to postgres";
      return nullptr;
    }
    pg->as_ = "runuser -u postgres -- ";
  }
  // A port per process: only the socket file name depends on it.
  pg->port_ = 20000 + static_cast<int>(getpid() % 30000);
  if (!pg->Run(absl::StrCat(pg->bin_, "/initdb -D ", pg->dir_, "/data -U covplan -A trust"))) {
    *why = absl::StrCat("initdb failed (log ", pg->dir_, "/cmd.log)");
    return nullptr;
  }
  if (!pg->Restart()) {
    *why = absl::StrCat("pg_ctl start failed (log ", pg->dir_, "/postgres.log)");
    return nullptr;
  }
  if (!pg->CreateDatabase("covplan")) {
    *why = "createdb failed";
    return nullptr;
  }
  return pg;
}

PgTestCluster::~PgTestCluster() {
  if (!dir_.empty()) {
    Run(absl::StrCat(bin_, "/pg_ctl -D ", dir_, "/data -m immediate stop"));
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
}

bool PgTestCluster::Run(const std::string& command) const {
  const std::string line = absl::StrCat(as_, command, " >>", dir_, "/cmd.log 2>&1");
  return std::system(line.c_str()) == 0;
}

std::string PgTestCluster::Conninfo(const std::string& database) const {
  return absl::StrCat("host=", dir_, " port=", port_, " dbname=", database,
                      " user=covplan connect_timeout=2");
}

bool PgTestCluster::CreateDatabase(const std::string& name) const {
  return Run(absl::StrCat(bin_, "/createdb -h ", dir_, " -p ", port_, " -U covplan ", name));
}

bool PgTestCluster::Stop() const {
  return Run(absl::StrCat(bin_, "/pg_ctl -D ", dir_, "/data -m fast -w stop"));
}

bool PgTestCluster::Restart() const {
  return Run(absl::StrCat(bin_, "/pg_ctl -D ", dir_, "/data -l ", dir_, "/postgres.log -w -o \"-k ",
                          dir_, " -p ", port_, " -c listen_addresses=''\" start"));
}

}  // namespace covplan::testing
