#include "server/tenant_tokens.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "api/digest.h"
#include "planner/common/status_macros.h"
#include "server/config_lines.h"

namespace covplan {
namespace {

constexpr size_t kTagHex = 16;
constexpr size_t kMaxTenantName = 64;
constexpr size_t kMaxTokenBytes = 4096;

bool IsLowerHex(absl::string_view s) {
  for (char c : s) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace

bool IsTenantName(absl::string_view s) {
  if (s.empty() || s.size() > kMaxTenantName) return false;
  for (char c : s) {
    if (!absl::ascii_isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.')
      return false;
  }
  return true;
}

absl::StatusOr<std::map<std::string, std::string>> TenantTokens::Parse(absl::string_view text) {
  std::map<std::string, std::string> table;
  RETURN_IF_ERROR(ForEachConfigLine(text, [&](const std::vector<absl::string_view>& fields) {
    if (fields.size() != 2 || fields[0].size() != 64 || !IsLowerHex(fields[0])) {
      return absl::InvalidArgumentError(
          "expected \"<sha256 of the token, 64 lowercase hex> <tenant>\"");
    }
    if (!IsTenantName(fields[1]))
      return absl::InvalidArgumentError("tenant must be 1-64 characters of [A-Za-z0-9._-]");
    if (!table.emplace(std::string(fields[0]), std::string(fields[1])).second)
      return absl::InvalidArgumentError("the same token hash twice");
    return absl::OkStatus();
  }));
  return table;
}

absl::StatusOr<std::unique_ptr<TenantTokens>> TenantTokens::Load(const std::string& path) {
  std::unique_ptr<TenantTokens> tokens(new TenantTokens(path));
  absl::StatusOr<size_t> loaded = tokens->Reload();
  if (!loaded.ok()) return loaded.status();
  return tokens;
}

absl::StatusOr<size_t> TenantTokens::Reload() {
  ASSIGN_OR_RETURN(const std::string text, ReadConfigFile("--token_file", path_));
  absl::StatusOr<std::map<std::string, std::string>> table = Parse(text);
  if (!table.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--token_file ", path_, ": ", table.status().message()));
  }
  absl::MutexLock lock(&mu_);
  tenant_by_hash_ = std::move(*table);
  return tenant_by_hash_.size();
}

absl::StatusOr<std::string> TenantTokens::Authenticate(absl::string_view authorization) const {
  if (authorization.empty()) {
    return absl::UnauthenticatedError(
        "missing credentials: send metadata \"authorization: Bearer <token>\"");
  }
  constexpr absl::string_view kBearer = "Bearer ";
  if (!absl::StartsWithIgnoreCase(authorization, kBearer) ||
      authorization.size() > kMaxTokenBytes) {
    return absl::UnauthenticatedError("authorization metadata is not \"Bearer <token>\"");
  }
  const absl::string_view token = absl::StripAsciiWhitespace(authorization.substr(kBearer.size()));
  const std::string hash = Sha256Hex(token);
  absl::MutexLock lock(&mu_);
  auto it = tenant_by_hash_.find(hash);
  if (token.empty() || it == tenant_by_hash_.end())
    return absl::UnauthenticatedError("invalid bearer token");
  return it->second;
}

size_t TenantTokens::size() const {
  absl::MutexLock lock(&mu_);
  return tenant_by_hash_.size();
}

std::string TenantTag(absl::string_view tenant) {
  if (tenant.empty()) return "";
  return Sha256Hex(absl::StrCat("covplan-tenant\n", tenant)).substr(0, kTagHex);
}

std::string ScopedMapId(const std::string& content_id, const std::string& tag) {
  if (tag.empty()) return content_id;
  return Sha256Hex(absl::StrCat("covplan-tenant-map\n", tag, "\n", content_id))
             .substr(0, 64 - kTagHex) +
         tag;
}

bool OwnsMap(const std::string& tag, absl::string_view map_id) {
  return tag.empty() || (map_id.size() == 64 && absl::EndsWith(map_id, tag));
}

std::string PlanIdSuffix(const std::string& tag) {
  return tag.empty() ? "" : absl::StrCat("-", tag);
}

bool OwnsPlan(const std::string& tag, absl::string_view plan_id) {
  return tag.empty() || absl::EndsWith(plan_id, PlanIdSuffix(tag));
}

}  // namespace covplan
