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
//   GET /v1/events?map_id=<id>   the map's live events (server/live_events.h)
//                                as Server-Sent Events: one LiveEvent per
//                                `data:` line, in the same JSON mapping
//
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
#include "server/live_events.h"
#include "server/metrics.h"
#include "server/tenant_tokens.h"

struct mg_context;
struct mg_connection;

namespace google::protobuf {
class Message;
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
  // Threads serving requests; each open event stream holds one (the
  // service's max_live_streams bounds them).
  int worker_threads = 48;
  // With --token_file (optional, outlives the gateway): every /v1/ request
  // must carry "Authorization: Bearer <token>" of a tenant, checked at the
  // door before its body is read (401 otherwise); the console's files stay
  // open, so the page can ask for the token. The call gate checks the token
  // again to learn the tenant.
  const TenantTokens* tokens = nullptr;
  // Where refusals at the door are counted (optional, outlives the gateway).
  ServerMetrics* metrics = nullptr;
};

class HttpGateway {
 public:
  // UNAVAILABLE naming the address when the port cannot be bound.
  // `live` (optional, outlives the gateway) feeds GET /v1/events.
  static absl::StatusOr<std::unique_ptr<HttpGateway>> Start(const HttpGatewayOptions& options,
                                                            std::shared_ptr<grpc::Channel> channel,
                                                            LiveEvents* live = nullptr);
  ~HttpGateway();
  HttpGateway(const HttpGateway&) = delete;
  HttpGateway& operator=(const HttpGateway&) = delete;

  int port() const { return port_; }

  // From now on every API call answers UNAVAILABLE without reaching gRPC,
  // and the event streams end (the LiveEvents hub closes); returns once the
  // calls already started are under way. Call before the gRPC server shuts
  // down.
  void StopCalls();

 private:
  HttpGateway(const HttpGatewayOptions& options, std::shared_ptr<grpc::Channel> channel,
              LiveEvents* live);
  static int HandleApi(mg_connection* conn, void* self);
  int Serve(mg_connection* conn);
  // With a token file: false once it answered 401 (the request's bearer
  // token is missing or unknown).
  bool Authenticated(mg_connection* conn, absl::string_view method);
  // GET / and the console's files (server/console_assets.h); 404 else.
  int ServeConsole(mg_connection* conn, absl::string_view uri);
  // GET /v1/events: the map's live events once GetMap says the caller may
  // read it; returns when the client goes or StopCalls.
  int ServeEvents(mg_connection* conn);
  // Calls `method` in process with the request's Authorization and
  // Grpc-Timeout headers; UNAVAILABLE once StopCalls.
  grpc::Status Invoke(mg_connection* conn, const google::protobuf::MethodDescriptor& method,
                      const google::protobuf::Message& request,
                      google::protobuf::Message* response);
  // Parses `body` as the method's request, calls it in process, answers.
  int Call(mg_connection* conn, const google::protobuf::MethodDescriptor& method,
           const std::string& body);

  HttpGatewayOptions options_;
  LiveEvents* const live_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<grpc::GenericStub> stub_;
  absl::Mutex calls_mu_;
  bool closing_ ABSL_GUARDED_BY(calls_mu_) = false;
  mg_context* ctx_ = nullptr;
  int port_ = 0;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_HTTP_GATEWAY_H_
