// Bearer tokens checked at the transport: a gRPC AuthMetadataProcessor on
// the listening port's credentials refuses every call that needs a token
// and does not carry a valid one with UNAUTHENTICATED, before gRPC reads its
// request message and before any handler runs. A refused call is counted in
// covplan_requests_total and logged like every other call (tenant
// "unauthenticated").
//
//   auto auth = std::make_shared<TransportAuth>(tokens, metrics);
//   ASSIGN_OR_RETURN(auto credentials, ListeningCredentials(config, auth));
//   builder.AddListeningPort(address, credentials);
//
// Calls that need no token: gRPC health checking and server reflection
// (probes and grpcurl's listing). Everything else does, the CoveragePlanner
// methods and Drive included, and so does any unknown method.
//
// What the processor does not do is hand the tenant to the handler: gRPC
// keeps one AuthContext per connection, so a property a processor adds is
// seen by every later call on that connection (grpc/grpc#28809). The call
// gate (server/call_gate.h) therefore looks the token up once more to learn
// the call's tenant; the processor only guarantees that no call without a
// valid token reaches it. Calls through the server's in-process channel (the
// JSON API, server/http_gateway.h) pass no processor: the gateway checks the
// token at its own door and the gate checks it again.
//
// Thread-safety: Process is called on gRPC's threads concurrently; it only
// reads the TenantTokens (thread-safe) and records metrics (thread-safe).
#ifndef COVPLAN_SERVER_TRANSPORT_AUTH_H_
#define COVPLAN_SERVER_TRANSPORT_AUTH_H_

#include <grpcpp/security/auth_metadata_processor.h>

#include <string>

#include "absl/strings/string_view.h"
#include "server/metrics.h"
#include "server/tenant_tokens.h"

namespace covplan {

class TransportAuth final : public grpc::AuthMetadataProcessor {
 public:
  // `tokens` and `metrics` outlive the processor (and so the gRPC server).
  TransportAuth(const TenantTokens* tokens, ServerMetrics* metrics)
      : tokens_(tokens), metrics_(metrics) {}

  // A hash lookup under a mutex: run inline on gRPC's thread.
  bool IsBlocking() const override { return false; }

  // OK when the call needs no token or carries a valid one; UNAUTHENTICATED
  // with the token check's reason otherwise. Consumes and adds no metadata.
  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata,
                       OutputMetadata* response_metadata) override;

 private:
  const TenantTokens* const tokens_;
  ServerMetrics* const metrics_;
};

// Whether a call to `path` ("/package.Service/Method") needs a bearer token.
bool PathNeedsToken(absl::string_view path);

// Counts and logs a call refused for its token before any handler ran, as
// the call gate records a call (metric with tenant "unauthenticated", one
// "request finished" line); `where` ("transport", "http") is logged as
// refused_at.
void RecordUnauthenticated(ServerMetrics* metrics, const std::string& method,
                           absl::string_view message, absl::string_view where);

}  // namespace covplan

#endif  // COVPLAN_SERVER_TRANSPORT_AUTH_H_
