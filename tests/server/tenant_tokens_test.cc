// TenantTokens (token-file parsing, bearer authentication, reload) and the
// tenant-scoped ids of server/tenant_tokens.h.
#include "server/tenant_tokens.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "api/digest.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

std::string Line(const std::string& token, const std::string& tenant) {
  return Sha256Hex(token) + " " + tenant + "\n";
}

TEST(TenantTokensTest, ParsesHashesAndRejectsMalformedLines) {
  absl::StatusOr<std::map<std::string, std::string>> table =
      TenantTokens::Parse("# comment\n\n" + Line("a", "fleet-a") + "  " + Line("b", "fleet_b.2"));
  ASSERT_TRUE(table.ok()) << table.status();
  EXPECT_EQ(table->size(), 2u);
  EXPECT_EQ(table->at(Sha256Hex("a")), "fleet-a");
  for (const std::string& bad :
       {std::string("abc fleet\n"), Sha256Hex("a") + "\n", Sha256Hex("a") + " bad/name\n",
        Line("a", "x") + Line("a", "y"), Sha256Hex("a") + " x y\n"}) {
    absl::StatusOr<std::map<std::string, std::string>> parsed = TenantTokens::Parse(bad);
    EXPECT_TRUE(absl::IsInvalidArgument(parsed.status())) << bad;
  }
  EXPECT_NE(TenantTokens::Parse("\n" + Line("a", "x") + "junk\n").status().message().find("line 3"),
            absl::string_view::npos);
}

TEST(TenantTokensTest, AuthenticatesBearerTokensAndReloads) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "covplan_tokens_test.txt").string();
  { std::ofstream(path) << Line("secret-a", "alpha"); }
  absl::StatusOr<std::unique_ptr<TenantTokens>> tokens = TenantTokens::Load(path);
  ASSERT_TRUE(tokens.ok()) << tokens.status();
  absl::StatusOr<std::string> tenant = (*tokens)->Authenticate("Bearer secret-a");
  ASSERT_TRUE(tenant.ok()) << tenant.status();
  EXPECT_EQ(*tenant, "alpha");
  EXPECT_TRUE(absl::IsUnauthenticated((*tokens)->Authenticate("").status()));
  EXPECT_TRUE(absl::IsUnauthenticated((*tokens)->Authenticate("secret-a").status()));
  EXPECT_TRUE(absl::IsUnauthenticated((*tokens)->Authenticate("Bearer secret-b").status()));
  EXPECT_TRUE(absl::IsUnauthenticated((*tokens)->Authenticate("Bearer ").status()));

  { std::ofstream(path) << Line("secret-b", "beta"); }
  ASSERT_TRUE((*tokens)->Reload().ok());
  EXPECT_TRUE(absl::IsUnauthenticated((*tokens)->Authenticate("Bearer secret-a").status()));
  EXPECT_EQ(*(*tokens)->Authenticate("Bearer secret-b"), "beta");
  { std::ofstream(path) << "garbage\n"; }
  EXPECT_FALSE((*tokens)->Reload().ok());
  EXPECT_EQ(*(*tokens)->Authenticate("Bearer secret-b"), "beta");  // kept
  std::remove(path.c_str());
  EXPECT_FALSE(TenantTokens::Load(path).ok());
}

TEST(TenantTokensTest, IdsCarryTheTenantTag) {
  const std::string content(64, 'a');
  EXPECT_EQ(TenantTag(""), "");
  EXPECT_EQ(ScopedMapId(content, ""), content);
  const std::string alpha = TenantTag("alpha"), beta = TenantTag("beta");
  ASSERT_EQ(alpha.size(), 16u);
  EXPECT_NE(alpha, beta);
  const std::string a = ScopedMapId(content, alpha), b = ScopedMapId(content, beta);
  EXPECT_EQ(a.size(), 64u);
  EXPECT_NE(a, b);
  EXPECT_EQ(a, ScopedMapId(content, alpha));  // deterministic: PutMap stays idempotent
  EXPECT_TRUE(OwnsMap(alpha, a));
  EXPECT_FALSE(OwnsMap(beta, a));
  EXPECT_FALSE(OwnsMap(alpha, content));
  EXPECT_TRUE(OwnsMap("", a));
  EXPECT_TRUE(OwnsPlan(alpha, "p-0123" + PlanIdSuffix(alpha)));
  EXPECT_FALSE(OwnsPlan(beta, "p-0123" + PlanIdSuffix(alpha)));
  EXPECT_FALSE(OwnsPlan(alpha, "p-0123"));
}

}  // namespace
}  // namespace covplan
