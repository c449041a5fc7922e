// How the service's absl::Status answers become gRPC statuses: the code is
// carried over as it is (absl and gRPC share the numbering), the message is
// bounded because it travels in trailing metadata, whose size the client
// limits (an over-long one would turn the real error into RESOURCE_EXHAUSTED
// on the client).
//
//   reactor->Finish(ToGrpc(status));
//   metrics->RecordRequest("Plan", CodeName(status), seconds);
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_SERVER_GRPC_STATUS_H_
#define COVPLAN_SERVER_GRPC_STATUS_H_

#include <string>

#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace covplan {

// `message` cut to kMaxMessageBytes (server/request_limits.h), marked as cut.
std::string BoundedMessage(absl::string_view message);

// A unary call's status, its message bounded.
grpc::Status ToGrpc(const absl::Status& status);

// A Drive session's end status: the message passed on unchanged (a session
// ends on its own short texts or on the status of its first plan).
grpc::Status ToGrpcUnbounded(const absl::Status& status);

// The gRPC name of the status code ("OK", "INVALID_ARGUMENT"), as metrics
// and logs name it.
std::string CodeName(const absl::Status& status);

}  // namespace covplan

#endif  // COVPLAN_SERVER_GRPC_STATUS_H_
