#include "server/transport_auth.h"

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "server/grpc_status.h"
#include "server/log.h"
#include "server/rpc_methods.h"

namespace covplan {
namespace {

absl::string_view Value(const grpc::AuthMetadataProcessor::InputMetadata& metadata,
                        absl::string_view key) {
  const auto it = metadata.find(grpc::string_ref(key.data(), key.size()));
  return it == metadata.end() ? absl::string_view()
                              : absl::string_view(it->second.data(), it->second.size());
}

}  // namespace

bool PathNeedsToken(absl::string_view path) {
  // Probes (Kubernetes, the router, `covplan health`) and grpcurl's listing
  // stay open, as they were before tokens moved to the transport.
  return !absl::StartsWith(path, "/grpc.health.v1.Health/") &&
         !absl::StartsWith(path, "/grpc.reflection.v1alpha.ServerReflection/");
}

void RecordUnauthenticated(ServerMetrics* metrics, const std::string& method,
                           absl::string_view message, absl::string_view where) {
  if (metrics != nullptr) metrics->RecordRequest(method, "UNAUTHENTICATED", 0.0, "unauthenticated");
  LogLine("warn", "request finished",
          {{"req", "-"},
           {"tenant", "unauthenticated"},
           {"method", method},
           {"code", "UNAUTHENTICATED"},
           {"ms", "0.0"},
           {"late", "false"},
           {"refused_at", std::string(where)},
           {"detail", BoundedMessage(message)}});
}

grpc::Status TransportAuth::Process(const InputMetadata& auth_metadata,
                                    grpc::AuthContext* /*context*/,
                                    OutputMetadata* /*consumed_auth_metadata*/,
                                    OutputMetadata* /*response_metadata*/) {
  const absl::string_view path = Value(auth_metadata, ":path");
  if (!PathNeedsToken(path)) return grpc::Status::OK;
  const absl::StatusOr<std::string> tenant =
      tokens_->Authenticate(Value(auth_metadata, "authorization"));
  if (tenant.ok()) return grpc::Status::OK;
  RecordUnauthenticated(metrics_, MethodLabel(path), tenant.status().message(), "transport");
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, std::string(tenant.status().message()));
}

}  // namespace covplan
