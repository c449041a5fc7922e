// The transport's token check (server/transport_auth.h) on its own: which
// paths need a token, what it answers for each kind of bad token, and the
// bounded method labels its refusals are counted under.
#include "server/transport_auth.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "api/digest.h"
#include "gtest/gtest.h"
#include "server/rpc_methods.h"

namespace covplan {
namespace {

class TransportAuthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "covplan_transport_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    std::ofstream(dir_ + "/tokens.txt") << Sha256Hex("alpha-token") << " alpha\n";
    absl::StatusOr<std::unique_ptr<TenantTokens>> tokens = TenantTokens::Load(dir_ + "/tokens.txt");
    ASSERT_TRUE(tokens.ok()) << tokens.status();
    tokens_ = std::move(*tokens);
    auth_ = std::make_unique<TransportAuth>(tokens_.get(), &metrics_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Process on a call to `path` with `authorization` (none when empty).
  grpc::Status Call(const std::string& path, const std::string& authorization) {
    grpc::AuthMetadataProcessor::InputMetadata metadata;
    metadata.emplace(":path", path);
    if (!authorization.empty()) metadata.emplace("authorization", authorization);
    grpc::AuthMetadataProcessor::OutputMetadata consumed;
    grpc::AuthMetadataProcessor::OutputMetadata response;
    const grpc::Status status = auth_->Process(metadata, nullptr, &consumed, &response);
    EXPECT_TRUE(consumed.empty());
    EXPECT_TRUE(response.empty());
    return status;
  }

  std::string dir_;
  ServerMetrics metrics_;
  std::unique_ptr<TenantTokens> tokens_;
  std::unique_ptr<TransportAuth> auth_;
};

TEST_F(TransportAuthTest, CoveragePlannerCallsNeedAValidBearerToken) {
  const std::string plan = "/covplan.v1.CoveragePlanner/Plan";
  EXPECT_TRUE(Call(plan, "Bearer alpha-token").ok());
  EXPECT_TRUE(Call(plan, "bearer alpha-token").ok()) << "the scheme is case-insensitive";
  const grpc::Status missing = Call(plan, "");
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_NE(missing.error_message().find("authorization: Bearer <token>"), std::string::npos)
      << missing.error_message();
  EXPECT_EQ(Call(plan, "Bearer beta-token").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Call(plan, "alpha-token").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Call("/covplan.v1.CoveragePlanner/Drive", "").error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Call("/x.Y/Z", "").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Call("", "").error_code(), grpc::StatusCode::UNAUTHENTICATED);
}

TEST_F(TransportAuthTest, HealthAndReflectionStayOpen) {
  EXPECT_TRUE(Call("/grpc.health.v1.Health/Check", "").ok());
  EXPECT_TRUE(Call("/grpc.health.v1.Health/Watch", "").ok());
  EXPECT_TRUE(Call("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", "").ok());
  EXPECT_FALSE(PathNeedsToken("/grpc.health.v1.Health/Check"));
  EXPECT_TRUE(PathNeedsToken("/grpc.health.v1.HealthX/Check"));
  EXPECT_TRUE(PathNeedsToken("/covplan.v1.CoveragePlanner/GetPlan"));
}

TEST(RpcMethods, LabelsAreTheServicesMethodsOrUnknown) {
  EXPECT_EQ(MethodLabel("/covplan.v1.CoveragePlanner/Plan"), "Plan");
  EXPECT_EQ(MethodLabel("/covplan.v1.CoveragePlanner/Drive"), "Drive");
  EXPECT_EQ(MethodLabel("/covplan.v1.CoveragePlanner/NoSuch"), "unknown");
  EXPECT_EQ(MethodLabel("/covplan.v1.CoveragePlannerX/Plan"), "unknown");
  EXPECT_EQ(MethodLabel("/x.Y/" + std::string(1000, 'a')), "unknown");
  EXPECT_EQ(MethodLabel(""), "unknown");
  ASSERT_NE(CoveragePlannerMethod("/covplan.v1.CoveragePlanner/PutMap"), nullptr);
  EXPECT_EQ(CoveragePlannerMethod("/covplan.v1.CoveragePlanner/PutMap")->input_type()->name(),
            "PutMapRequest");
}

}  // namespace
}  // namespace covplan
