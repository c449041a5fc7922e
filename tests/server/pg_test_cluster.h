// A throwaway PostgreSQL cluster for tests: initdb in a temp dir, pg_ctl on
// a unix socket only (no TCP), trust auth for user "covplan"; removed on
// destruction. Run as root, the server binaries run as the "postgres" user
// (PostgreSQL refuses root).
//
//   std::string why;
//   std::unique_ptr<PgTestCluster> pg = PgTestCluster::Start(&why);
//   if (pg == nullptr) GTEST_SKIP() << why;
//   PgMapStore::Open(pg->Conninfo("covplan"));
//
// Thread-safety: not thread-safe; one per test process.
#ifndef COVPLAN_TESTS_SERVER_PG_TEST_CLUSTER_H_
#define COVPLAN_TESTS_SERVER_PG_TEST_CLUSTER_H_

#include <memory>
#include <string>

namespace covplan::testing {

class PgTestCluster {
 public:
  // nullptr (with the reason in *why) when no PostgreSQL server binaries
  // are installed or the cluster cannot be started.
  static std::unique_ptr<PgTestCluster> Start(std::string* why);
  ~PgTestCluster();

  std::string Conninfo(const std::string& database) const;
  bool CreateDatabase(const std::string& name) const;
  bool Stop() const;     // fast shutdown; the data stays
  bool Restart() const;  // start again on the same socket

 private:
  PgTestCluster() = default;
  bool Run(const std::string& command) const;

  std::string bin_;  // directory of initdb / pg_ctl
  std::string dir_;  // temp dir: data/ and the socket
  std::string as_;   // "runuser -u postgres -- " when root, else ""
  int port_ = 0;
};

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_PG_TEST_CLUSTER_H_
