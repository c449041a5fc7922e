#include "server/tenant_quotas.h"

#include <limits>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "planner/common/status_macros.h"
#include "server/config_lines.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

// Sets one `name=value` field of `quota`.
absl::Status SetField(absl::string_view field, TenantQuota* quota) {
  const std::pair<absl::string_view, absl::string_view> kv =
      absl::StrSplit(field, absl::MaxSplits('=', 1));
  int64_t value = 0;
  if (!absl::SimpleAtoi(kv.second, &value) || value < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("\"", field.substr(0, 64), "\": expected name=N with N a whole number >= 0"));
  }
  const int64_t int_max = std::numeric_limits<int>::max();
  if (kv.first == "max_solves" && value <= int_max) {
    quota->max_solves = static_cast<int>(value);
  } else if (kv.first == "max_queued" && value <= int_max) {
    quota->max_queued = static_cast<int>(value);
  } else if (kv.first == "max_maps") {
    quota->max_maps = value;
  } else if (kv.first == "max_solves" || kv.first == "max_queued") {
    return absl::InvalidArgumentError(absl::StrCat(kv.first, " is too large"));
  } else {
    return absl::InvalidArgumentError(absl::StrCat("unknown quota \"", kv.first.substr(0, 64),
                                                   "\" (known: max_solves, max_queued, max_maps)"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::map<std::string, TenantQuota>> TenantQuotas::Parse(
    absl::string_view text, const TenantQuota& defaults) {
  std::map<std::string, TenantQuota> table;
  RETURN_IF_ERROR(ForEachConfigLine(text, [&](const std::vector<absl::string_view>& fields) {
    if (!IsTenantName(fields[0])) {
      return absl::InvalidArgumentError(
          "expected \"<tenant> name=N ...\", the tenant being 1-64 characters of "
          "[A-Za-z0-9._-]");
    }
    const std::string tenant(fields[0]);
    if (table.count(tenant) != 0)
      return absl::InvalidArgumentError(absl::StrCat("tenant ", tenant, " twice"));
    if (fields.size() == 1)
      return absl::InvalidArgumentError(absl::StrCat("tenant ", tenant, " sets no quota"));
    TenantQuota quota = defaults;
    for (size_t k = 1; k < fields.size(); ++k) RETURN_IF_ERROR(SetField(fields[k], &quota));
    table.emplace(tenant, quota);
    return absl::OkStatus();
  }));
  return table;
}

absl::StatusOr<std::unique_ptr<TenantQuotas>> TenantQuotas::Load(const TenantQuota& defaults,
                                                                 const std::string& path) {
  std::unique_ptr<TenantQuotas> quotas(new TenantQuotas(defaults, path));
  if (absl::StatusOr<size_t> loaded = quotas->Reload(); !loaded.ok()) return loaded.status();
  return quotas;
}

absl::StatusOr<size_t> TenantQuotas::Reload() {
  if (path_.empty()) return 0;
  ASSIGN_OR_RETURN(const std::string text, ReadConfigFile("--tenant_quota_file", path_));
  absl::StatusOr<std::map<std::string, TenantQuota>> table = Parse(text, defaults_);
  if (!table.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--tenant_quota_file ", path_, ": ", table.status().message()));
  }
  std::map<std::string, TenantQuota> by_tag;
  for (const auto& [tenant, quota] : *table) by_tag.emplace(TenantTag(tenant), quota);
  absl::MutexLock lock(&mu_);
  by_tag_ = std::move(by_tag);
  return by_tag_.size();
}

TenantQuota TenantQuotas::For(const std::string& tenant_tag) const {
  absl::MutexLock lock(&mu_);
  const auto it = by_tag_.find(tenant_tag);
  return it == by_tag_.end() ? defaults_ : it->second;
}

}  // namespace covplan
