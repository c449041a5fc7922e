// Per-client bearer tokens bound to tenants, and tenant-scoped ids.
//
// The token file (covplan-server --token_file) holds one token per line as
// the SHA-256 hex of the token and the tenant it speaks for:
//
//   # sha256(token)                                                  tenant
//   9f86d081884c7d659a2feaa0c55ad015a3bf4f1b2b0b822cd15d6c15b0f00a08 fleet-a
//
// generated with e.g. `printf %s "$TOKEN" | sha256sum`. Only hashes are kept
// on disk and in memory; a call's token is hashed and looked up.
//
//   absl::StatusOr<std::unique_ptr<TenantTokens>> tokens = TenantTokens::Load(path);
//   absl::StatusOr<std::string> tenant = (*tokens)->Authenticate(authorization_header);
//   (*tokens)->Reload();  // on SIGHUP; a bad file keeps the previous table
//
// Ownership is carried by the ids themselves, so it needs no store schema and
// survives restarts: each tenant has a 16-hex tag (a digest of its name). A
// tenant's map id is 48 hex of a digest of (tag, content id) followed by the
// tag, so two tenants storing the same map get two ids and both can use and
// delete theirs; a tenant's plan ids end in "-<tag>". A call whose id does
// not carry its tag is answered exactly as for an id that does not exist.
// Without a token file the tag is empty and ids are as before.
//
// Thread-safety: TenantTokens is thread-safe (Reload swaps the table under a
// lock); the free functions are stateless.
#ifndef COVPLAN_SERVER_TENANT_TOKENS_H_
#define COVPLAN_SERVER_TENANT_TOKENS_H_

#include <map>
#include <memory>
#include <string>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"

namespace covplan {

class TenantTokens {
 public:
  // Unreadable or malformed file → InvalidArgument naming the line.
  static absl::StatusOr<std::unique_ptr<TenantTokens>> Load(const std::string& path);
  // Parses token-file text (for Load, Reload and tests).
  static absl::StatusOr<std::map<std::string, std::string>> Parse(absl::string_view text);

  // Rereads the file; on error the previous table stays in force.
  // Returns the number of tokens now loaded.
  absl::StatusOr<size_t> Reload();
  // The tenant of an `authorization` metadata value ("Bearer <token>"), or
  // Unauthenticated (missing header, not a bearer token, unknown token).
  absl::StatusOr<std::string> Authenticate(absl::string_view authorization) const;
  size_t size() const;

 private:
  explicit TenantTokens(std::string path) : path_(std::move(path)) {}
  const std::string path_;
  mutable absl::Mutex mu_;
  std::map<std::string, std::string> tenant_by_hash_ ABSL_GUARDED_BY(mu_);
};

// Whether `s` is a valid tenant name: 1-64 characters of [A-Za-z0-9._-].
bool IsTenantName(absl::string_view s);
// The tag of a tenant ("" for none: no token file).
std::string TenantTag(absl::string_view tenant);
// The id a tenant's map of content id `content_id` is stored under.
std::string ScopedMapId(const std::string& content_id, const std::string& tag);
// Whether `map_id` / `plan_id` belongs to the tenant with `tag` (always for "").
bool OwnsMap(const std::string& tag, absl::string_view map_id);
bool OwnsPlan(const std::string& tag, absl::string_view plan_id);
// The suffix a tenant's plan ids carry ("" for none).
std::string PlanIdSuffix(const std::string& tag);

}  // namespace covplan

#endif  // COVPLAN_SERVER_TENANT_TOKENS_H_
