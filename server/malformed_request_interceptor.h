// Gives malformed requests a status, a log line and a metric like every
// other call. gRPC's callback API answers a request that does not parse as
// its protobuf with UNIMPLEMENTED and an empty message, before any handler
// (ours included) sees it; this server interceptor rewrites that reply of a
// CoveragePlanner unary method to INVALID_ARGUMENT naming the expected
// message, logs it and counts it in covplan_requests_total.
//
//   builder.experimental().SetInterceptorCreators(MalformedRequestInterceptors(metrics));
//
// Thread-safety: the factory is shared by all calls; each interceptor
// belongs to one call.
#ifndef COVPLAN_SERVER_MALFORMED_REQUEST_INTERCEPTOR_H_
#define COVPLAN_SERVER_MALFORMED_REQUEST_INTERCEPTOR_H_

#include <grpcpp/support/server_interceptor.h>

#include <memory>
#include <vector>

#include "server/metrics.h"

namespace covplan {

std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>>
MalformedRequestInterceptors(ServerMetrics* metrics);

}  // namespace covplan

#endif  // COVPLAN_SERVER_MALFORMED_REQUEST_INTERCEPTOR_H_
