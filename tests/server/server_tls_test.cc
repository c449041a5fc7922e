// TLS and mutual TLS on covplan-server's gRPC port, against a real process
// with certificates made by the openssl CLI in a temporary directory: the
// right CA connects, a wrong CA does not; with --tls_client_ca a client
// without a certificate is refused and one with a certificate from that CA
// is served.
#include <grpcpp/grpcpp.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/server_process.h"

namespace covplan {
namespace {

using ::covplan::testing::HealthStatus;
using ::covplan::testing::ServerProcess;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class ServerTlsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "covplan_tls_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    // Two CAs; a server certificate for 127.0.0.1 and a client certificate,
    // both signed by the first.
    const std::string script = absl::StrCat(
        "set -e; cd ", dir_, "; exec >openssl.log 2>&1\n",
        "key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out $1.key; "
        "}\n",
        "for ca in ca other; do key $ca; openssl req -x509 -new -key $ca.key -out $ca.pem -days 2 "
        "-subj /CN=$ca; done\n",
        "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.cnf\n",
        "for who in server client; do key $who; openssl req -new -key $who.key -out $who.csr -subj "
        "/CN=$who; "
        "openssl x509 -req -in $who.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out $who.pem "
        "-days 2 "
        "-extfile san.cnf; done\n");
    if (std::system(("bash -c '" + script + "'").c_str()) != 0) {
      GTEST_SKIP() << "openssl could not make test certificates: "
                   << ReadFile(dir_ + "/openssl.log");
    }
  }
  void TearDown() override {
    server_.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  void StartServer(bool mutual) {
    server_ = std::make_unique<ServerProcess>();
    std::vector<std::string> args = {"--metrics_port=-1", "--drain_notice_s=0",
                                     "--tls_cert=" + dir_ + "/server.pem",
                                     "--tls_key=" + dir_ + "/server.key"};
    if (mutual) args.push_back("--tls_client_ca=" + dir_ + "/ca.pem");
    const absl::Status started = server_->Start(dir_ + "/maps", args);
    ASSERT_TRUE(started.ok()) << started;
  }
  // SERVING (1) over TLS trusting `ca`, optionally with the client certificate.
  absl::StatusOr<int> Health(const std::string& ca, bool client_cert) {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = ReadFile(dir_ + "/" + ca + ".pem");
    if (client_cert) {
      options.pem_cert_chain = ReadFile(dir_ + "/client.pem");
      options.pem_private_key = ReadFile(dir_ + "/client.key");
    }
    auto channel = grpc::CreateChannel(server_->target(), grpc::SslCredentials(options));
    return HealthStatus(channel, "");
  }
  std::string dir_;
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(ServerTlsTest, TheRightCaConnectsAWrongOneDoesNot) {
  StartServer(/*mutual=*/false);
  absl::StatusOr<int> ok = Health("ca", false);
  ASSERT_TRUE(ok.ok()) << ok.status();
  EXPECT_EQ(*ok, 1);
  EXPECT_FALSE(Health("other", false).ok());
  // Plaintext to a TLS port fails too.
  auto plain = grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials());
  EXPECT_FALSE(HealthStatus(plain, "").ok());
}

TEST_F(ServerTlsTest, MutualTlsRefusesAClientWithoutACertificate) {
  StartServer(/*mutual=*/true);
  EXPECT_FALSE(Health("ca", /*client_cert=*/false).ok());
  absl::StatusOr<int> ok = Health("ca", /*client_cert=*/true);
  ASSERT_TRUE(ok.ok()) << ok.status();
  EXPECT_EQ(*ok, 1);
}

TEST_F(ServerTlsTest, TlsFlagsAreChecked) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--tls_cert=" + dir_ + "/server.pem"},
        std::vector<std::string>{"--tls_client_ca=" + dir_ + "/ca.pem"}}) {
    ServerProcess server;
    EXPECT_FALSE(server.Start(dir_ + "/maps", args).ok());
    EXPECT_EQ(server.start_exit_status(), 2) << server.log();
  }
  ServerProcess server;  // a key that is not PEM
  EXPECT_FALSE(server
                   .Start(dir_ + "/maps",
                          {"--tls_cert=" + dir_ + "/server.pem", "--tls_key=" + dir_ + "/san.cnf"})
                   .ok());
  EXPECT_NE(server.log().find("not a readable PEM file"), std::string::npos) << server.log();
}

}  // namespace
}  // namespace covplan
