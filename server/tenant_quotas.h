// Per-tenant quotas: how many solves a tenant may run at once, how many more
// may wait for a worker, and how many maps it may store. A default for every
// tenant (covplan-server --tenant_max_solves, --tenant_max_queued,
// --tenant_max_maps) and per-tenant overrides from a file
// (--tenant_quota_file), one tenant per line, the fields it sets:
//
//   # tenant   quotas (0: no limit; an unset field keeps the default)
//   fleet-a    max_solves=1 max_queued=2 max_maps=50
//   fleet-b    max_maps=0
//
//   absl::StatusOr<std::unique_ptr<TenantQuotas>> quotas =
//       TenantQuotas::Load(defaults, path);   // path "" = defaults only
//   TenantQuota q = (*quotas)->For(call.tenant_tag);
//   (*quotas)->Reload();  // on SIGHUP; a bad file keeps the previous table
//
// Tenants are looked up by tag (server/tenant_tokens.h), which every call and
// Drive session carries; without a token file every caller is the one tenant
// with the empty tag and gets the defaults.
//
// Thread-safety: TenantQuotas is thread-safe (Reload swaps under a lock).
#ifndef COVPLAN_SERVER_TENANT_QUOTAS_H_
#define COVPLAN_SERVER_TENANT_QUOTAS_H_

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"

namespace covplan {

// 0 in a field: no limit.
struct TenantQuota {
  int max_solves = 0;    // solves running at once (the pool never runs more)
  int max_queued = 0;    // admitted solves waiting for a worker beyond those
  int64_t max_maps = 0;  // maps stored

  bool operator==(const TenantQuota& o) const {
    return max_solves == o.max_solves && max_queued == o.max_queued && max_maps == o.max_maps;
  }
};

class TenantQuotas {
 public:
  // `path` "" → the defaults for everyone. An unreadable or malformed file →
  // InvalidArgument naming the line.
  static absl::StatusOr<std::unique_ptr<TenantQuotas>> Load(const TenantQuota& defaults,
                                                            const std::string& path);
  // Parses quota-file text over `defaults`: tenant name → its quota.
  static absl::StatusOr<std::map<std::string, TenantQuota>> Parse(absl::string_view text,
                                                                  const TenantQuota& defaults);

  // Rereads the file (nothing to do without one); on error the previous
  // table stays in force. Returns the number of tenants with overrides.
  absl::StatusOr<size_t> Reload();
  // The quota of the tenant with this tag.
  TenantQuota For(const std::string& tenant_tag) const;
  const TenantQuota& defaults() const { return defaults_; }
  bool has_file() const { return !path_.empty(); }

 private:
  TenantQuotas(const TenantQuota& defaults, std::string path)
      : defaults_(defaults), path_(std::move(path)) {}
  const TenantQuota defaults_;
  const std::string path_;
  mutable absl::Mutex mu_;
  std::map<std::string, TenantQuota> by_tag_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_TENANT_QUOTAS_H_
