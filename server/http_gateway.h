// The JSON API: every unary method of covplan.v1.CoveragePlanner over HTTP,
// served by civetweb (Debian's libcivetweb), in protobuf's own JSON mapping
// of the same request and response messages, so the two APIs cannot drift:
//
//   POST /v1/<Method>          e.g. /v1/Plan, /v1/GetPlan, /v1/ListMaps
//   Authorization: Bearer <token>       (with --token_file, as on gRPC)
//   Grpc-Timeout: 5S                    (optional deadline, gRPC's format)
//   {"mapId": "...", ...}               the request message as JSON
//
// and GET / serves the web console (server/console/, compiled in). The API
// answers 200 with the response message as JSON, or an error as
//   {"code": 3, "status": "INVALID_ARGUMENT", "message": "..."}
// with the HTTP status gRPC's code maps to (400, 401, 404, 429, 503, ...).
// Each call goes through an in-process channel into the running gRPC
// server, so tokens, tenants, request bounds, admission, deadlines, metrics
// and logs are exactly gRPC's. Streaming methods (Drive) answer 501.
//
//   ASSIGN_OR_RETURN(std::unique_ptr<HttpGateway> http,
//                    HttpGateway::Start(options, server->InProcessChannel(args)));
//   http->port();  // the bound port (options.port 0 picks one)
//   http.reset();  // stops listening; waits for the handlers in flight
//
// Thread-safety: civetweb runs handlers on its own worker threads; the
// gateway holds no mutable state of its own.
#ifndef COVPLAN_SERVER_HTTP_GATEWAY_H_
#define COVPLAN_SERVER_HTTP_GATEWAY_H_

#include <cstdint>
#include <memory>
#include <string>

#include <grpcpp/channel.h>
#include <grpcpp/generic/generic_stub.h>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"

struct mg_context;
struct mg_connection;

namespace google::protobuf {
class MethodDescriptor;
}  // namespace google::protobuf

namespace covplan {

struct HttpGatewayOptions {
  std::string address = "127.0.0.1";
  int port = 0;  // 0: pick a free port
  // The largest request body accepted (413 beyond), as gRPC's
  // max_message_bytes.
  int64_t max_body_bytes = 80 << 20;
  // A client that sends its request (headers and body) slower than this is
  // cut off, so slow clients cannot hold the worker threads.
  int request_timeout_ms = 15000;
  int worker_threads = 8;
};

class HttpGateway {
 public:
  // UNAVAILABLE naming the address when the port cannot be bound.
  static absl::StatusOr<std::unique_ptr<HttpGateway>> Start(const HttpGatewayOptions& options,
                                                            std::shared_ptr<grpc::Channel> channel);
  ~HttpGateway();
  HttpGateway(const HttpGateway&) = delete;
  HttpGateway& operator=(const HttpGateway&) = delete;

  int port() const { return port_; }

  // From now on every API call answers UNAVAILABLE without reaching gRPC;
  // returns once the calls already started are under way. Call before the
  // gRPC server shuts down.
  void StopCalls();

 private:
  explicit HttpGateway(const HttpGatewayOptions& options, std::shared_ptr<grpc::Channel> channel);
  static int HandleApi(mg_connection* conn, void* self);
  int Serve(mg_connection* conn);
  // GET / and the console's files (server/console_assets.h); 404 else.
  int ServeConsole(mg_connection* conn, absl::string_view uri);
  // Parses `body` as the method's request, calls it in process, answers.
  int Call(mg_connection* conn, const google::protobuf::MethodDescriptor& method,
           const std::string& body);

  HttpGatewayOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<grpc::GenericStub> stub_;
  absl::Mutex calls_mu_;
  bool closing_ ABSL_GUARDED_BY(calls_mu_) = false;
  mg_context* ctx_ = nullptr;
  int port_ = 0;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_HTTP_GATEWAY_H_
