#include "server/http_gateway.h"

#include <civetweb.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/message.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/channel.h>
#include <grpcpp/client_context.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/support/byte_buffer.h>

#include <chrono>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/notification.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "server/console_assets.h"
#include "server/grpc_status.h"
#include "server/log.h"
#include "server/rpc_methods.h"
#include "server/transport_auth.h"

namespace covplan {
namespace {

namespace pb = google::protobuf;

constexpr absl::string_view kApiPrefix = "/v1/";
// The live event stream (server/live_events.h), beside the methods.
constexpr absl::string_view kEventsPath = "/v1/events";
const std::string kEmptyObject = "{}";

// gRPC's code as an HTTP status (the mapping of google.rpc.Code).
int HttpStatusOf(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return 200;
    case grpc::StatusCode::CANCELLED:
      return 499;
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::OUT_OF_RANGE:
      return 400;
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return 504;
    case grpc::StatusCode::NOT_FOUND:
      return 404;
    case grpc::StatusCode::ALREADY_EXISTS:
    case grpc::StatusCode::ABORTED:
      return 409;
    case grpc::StatusCode::PERMISSION_DENIED:
      return 403;
    case grpc::StatusCode::UNAUTHENTICATED:
      return 401;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return 429;
    case grpc::StatusCode::UNIMPLEMENTED:
      return 501;
    case grpc::StatusCode::UNAVAILABLE:
      return 503;
    default:  // UNKNOWN, INTERNAL, DATA_LOSS
      return 500;
  }
}

void SendBody(mg_connection* conn, int http_status, const std::string& body, bool close) {
  mg_response_header_start(conn, http_status);
  mg_response_header_add(conn, "Content-Type", "application/json", -1);
  mg_response_header_add(conn, "Content-Length", absl::StrCat(body.size()).c_str(), -1);
  mg_response_header_add(conn, "Cache-Control", "no-store", -1);
  if (close) mg_disable_connection_keep_alive(conn);
  mg_response_header_send(conn);
  mg_write(conn, body.data(), body.size());
}

// An error as {"code": N, "status": "NAME", "message": "..."} (the JSON of
// google.rpc.Status without details), with the HTTP status of its code.
int SendError(mg_connection* conn, grpc::StatusCode code, const std::string& message,
              bool close = false, int http_status = 0) {
  pb::Struct error;
  (*error.mutable_fields())["code"].set_number_value(static_cast<int>(code));
  (*error.mutable_fields())["status"].set_string_value(
      CodeName(absl::Status(static_cast<absl::StatusCode>(code), "")));
  (*error.mutable_fields())["message"].set_string_value(BoundedMessage(message));
  std::string body;
  if (!pb::util::MessageToJsonString(error, &body).ok()) body = "{}";
  if (http_status == 0) http_status = HttpStatusOf(code);
  SendBody(conn, http_status, body, close);
  return http_status;
}

// gRPC's timeout format ("5S", "250m": at most 8 digits and a unit of
// H, M, S, m, u, n).
bool ParseGrpcTimeout(absl::string_view text, std::chrono::nanoseconds* out) {
  if (text.size() < 2 || text.size() > 9) return false;
  int64_t value = 0;
  if (!absl::SimpleAtoi(text.substr(0, text.size() - 1), &value) || value < 0) return false;
  // Beyond a day is no client deadline (the server's --max_request_s bounds
  // the call); also keeps the nanosecond count from overflowing.
  if ((text.back() == 'H' && value > 24) || (text.back() == 'M' && value > 24 * 60)) {
    *out = std::chrono::nanoseconds::max();
    return true;
  }
  switch (text.back()) {
    case 'H':
      *out = std::chrono::hours(value);
      return true;
    case 'M':
      *out = std::chrono::minutes(value);
      return true;
    case 'S':
      *out = std::chrono::seconds(value);
      return true;
    case 'm':
      *out = std::chrono::milliseconds(value);
      return true;
    case 'u':
      *out = std::chrono::microseconds(value);
      return true;
    case 'n':
      *out = std::chrono::nanoseconds(value);
      return true;
    default:
      return false;
  }
}

bool PrintableAscii(absl::string_view s) {
  for (char c : s) {
    if (c < 0x20 || c > 0x7e) return false;
  }
  return true;
}

// The body's fate: read whole, over `max` bytes, or cut short (the client
// stalled past the request timeout, went away, or sent less than its
// Content-Length).
enum class Body { kRead, kTooLarge, kIncomplete };

// Reads the whole body within `deadline_ms` of the call in all (civetweb's
// timeout restarts with each read; a client trickling bytes is cut off here).
Body ReadBody(mg_connection* conn, int64_t max, int64_t content_length, int deadline_ms,
              std::string* body) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(deadline_ms);
  char buf[16384];
  while (true) {
    const int n = mg_read(conn, buf, sizeof(buf));
    if (n < 0) return Body::kIncomplete;
    if (n == 0) break;
    body->append(buf, static_cast<size_t>(n));
    if (static_cast<int64_t>(body->size()) > max) return Body::kTooLarge;
    if (std::chrono::steady_clock::now() > deadline) return Body::kIncomplete;
  }
  if (content_length >= 0 && static_cast<int64_t>(body->size()) != content_length) {
    return Body::kIncomplete;
  }
  return Body::kRead;
}

grpc::ByteBuffer ToByteBuffer(const pb::Message& message) {
  const std::string bytes = message.SerializeAsString();
  grpc::Slice slice(bytes);
  return grpc::ByteBuffer(&slice, 1);
}

bool FromByteBuffer(const grpc::ByteBuffer& buffer, pb::Message* message) {
  std::vector<grpc::Slice> slices;
  if (!buffer.Dump(&slices).ok()) return false;
  std::string bytes;
  for (const grpc::Slice& s : slices)
    bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return message->ParseFromString(bytes);
}

}  // namespace

HttpGateway::HttpGateway(const HttpGatewayOptions& options, std::shared_ptr<grpc::Channel> channel,
                         LiveEvents* live)
    : options_(options),
      live_(live),
      channel_(std::move(channel)),
      stub_(std::make_unique<grpc::GenericStub>(channel_)) {}

absl::StatusOr<std::unique_ptr<HttpGateway>> HttpGateway::Start(
    const HttpGatewayOptions& options, std::shared_ptr<grpc::Channel> channel, LiveEvents* live) {
  std::unique_ptr<HttpGateway> gateway(new HttpGateway(options, std::move(channel), live));
  // Once per process, never undone: prometheus-cpp's Exposer shares
  // civetweb's process-wide state.
  static std::once_flag civetweb_initialised;
  std::call_once(civetweb_initialised, [] { mg_init_library(0); });
  const std::string ports = absl::StrCat(options.address, ":", options.port);
  const std::string threads = absl::StrCat(options.worker_threads);
  const std::string timeout = absl::StrCat(options.request_timeout_ms);
  const char* civet_options[] = {
      "listening_ports", ports.c_str(),       "num_threads", threads.c_str(), "request_timeout_ms",
      timeout.c_str(),   "enable_keep_alive", "yes",         nullptr};
  mg_callbacks callbacks{};
  // civetweb's own messages (a port it cannot bind) go to the structured log.
  callbacks.log_message = [](const mg_connection*, const char* message) {
    LogLine("warn", "http server", {{"detail", message}});
    return 1;
  };
  gateway->ctx_ = mg_start(&callbacks, gateway.get(), civet_options);
  if (gateway->ctx_ == nullptr) {
    return absl::UnavailableError(
        absl::StrCat("cannot serve HTTP on ", ports, " (port in use or bad address)"));
  }
  mg_server_port bound[4] = {};
  const int n = mg_get_server_ports(gateway->ctx_, 4, bound);
  gateway->port_ = n > 0 ? bound[0].port : options.port;
  mg_set_request_handler(gateway->ctx_, "/", &HttpGateway::HandleApi, gateway.get());
  return gateway;
}

HttpGateway::~HttpGateway() {
  StopCalls();
  if (ctx_ != nullptr) mg_stop(ctx_);
}

void HttpGateway::StopCalls() {
  {
    absl::MutexLock lock(&calls_mu_);
    closing_ = true;
  }
  if (live_ != nullptr) live_->Close();  // the event streams end
}

int HttpGateway::HandleApi(mg_connection* conn, void* self) {
  return static_cast<HttpGateway*>(self)->Serve(conn);
}

int HttpGateway::Serve(mg_connection* conn) {
  const mg_request_info* request = mg_get_request_info(conn);
  const absl::string_view uri = request->local_uri != nullptr ? request->local_uri : "";
  if (!absl::StartsWith(uri, kApiPrefix)) return ServeConsole(conn, uri);
  const std::string method_name(uri.substr(kApiPrefix.size()));
  if (!Authenticated(conn, uri == kEventsPath ? "events" : method_name)) return 401;
  if (uri == kEventsPath) return ServeEvents(conn);
  const pb::ServiceDescriptor* service = pb::DescriptorPool::generated_pool()->FindServiceByName(
      v1::CoveragePlanner::service_full_name());
  const pb::MethodDescriptor* method =
      service != nullptr ? service->FindMethodByName(method_name) : nullptr;
  if (method == nullptr) {
    return SendError(
        conn, grpc::StatusCode::NOT_FOUND,
        absl::StrCat("no method ", method_name, " in ", v1::CoveragePlanner::service_full_name()),
        /*close=*/true);
  }
  if (method->client_streaming() || method->server_streaming()) {
    return SendError(conn, grpc::StatusCode::UNIMPLEMENTED,
                     absl::StrCat(method->full_name(),
                                  " is a stream; the JSON API serves the unary methods (use gRPC "
                                  "for it)"),
                     /*close=*/true);
  }
  if (absl::string_view(request->request_method) != "POST") {
    return SendError(conn, grpc::StatusCode::UNIMPLEMENTED,
                     absl::StrCat(request->request_method, " ", uri,
                                  ": the JSON API takes POST with the request as a JSON body"),
                     /*close=*/true, /*http_status=*/405);
  }
  if (request->content_length > options_.max_body_bytes) {
    return SendError(conn, grpc::StatusCode::RESOURCE_EXHAUSTED,
                     absl::StrCat("request body of ", request->content_length,
                                  " bytes exceeds the server's limit of ", options_.max_body_bytes),
                     /*close=*/true, /*http_status=*/413);
  }
  if (const char* type = mg_get_header(conn, "Content-Type");
      type == nullptr || !absl::StartsWith(absl::AsciiStrToLower(type), "application/json")) {
    // Also keeps other sites' pages from posting to a local server (a
    // cross-origin JSON post needs a CORS preflight, which is never granted).
    return SendError(conn, grpc::StatusCode::INVALID_ARGUMENT,
                     "the JSON API takes Content-Type: application/json", /*close=*/true,
                     /*http_status=*/415);
  }
  std::string body;
  switch (ReadBody(conn, options_.max_body_bytes, request->content_length,
                   options_.request_timeout_ms, &body)) {
    case Body::kTooLarge:
      return SendError(conn, grpc::StatusCode::RESOURCE_EXHAUSTED,
                       absl::StrCat("request body exceeds the server's limit of ",
                                    options_.max_body_bytes, " bytes"),
                       /*close=*/true, /*http_status=*/413);
    case Body::kIncomplete:
      return SendError(
          conn, grpc::StatusCode::INVALID_ARGUMENT,
          absl::StrCat("the request body ended early (", body.size(), " of ",
                       request->content_length, " bytes) or came slower than the request timeout"),
          /*close=*/true, /*http_status=*/408);
    case Body::kRead:
      break;
  }
  return Call(conn, *method, body);
}

bool HttpGateway::Authenticated(mg_connection* conn, absl::string_view method) {
  if (options_.tokens == nullptr) return true;
  const char* authorization = mg_get_header(conn, "Authorization");
  const absl::StatusOr<std::string> tenant =
      options_.tokens->Authenticate(authorization != nullptr ? authorization : "");
  if (tenant.ok()) return true;
  const std::string label =
      method == "events"
          ? "events"
          : MethodLabel(absl::StrCat("/", v1::CoveragePlanner::service_full_name(), "/", method));
  RecordUnauthenticated(options_.metrics, label, tenant.status().message(), "http");
  SendError(conn, grpc::StatusCode::UNAUTHENTICATED, std::string(tenant.status().message()),
            /*close=*/true);
  return false;
}

int HttpGateway::ServeConsole(mg_connection* conn, absl::string_view uri) {
  const absl::string_view method = mg_get_request_info(conn)->request_method;
  const absl::string_view path = uri == "/" ? absl::string_view("/index.html") : uri;
  for (const ConsoleAsset& asset : ConsoleAssets()) {
    if (asset.path != path) continue;
    if (method != "GET" && method != "HEAD") {
      return SendError(conn, grpc::StatusCode::UNIMPLEMENTED,
                       absl::StrCat(method, " ", uri, ": the console's files take GET"),
                       /*close=*/true, /*http_status=*/405);
    }
    mg_response_header_start(conn, 200);
    mg_response_header_add(conn, "Content-Type", std::string(asset.content_type).c_str(), -1);
    mg_response_header_add(conn, "Content-Length", absl::StrCat(asset.size).c_str(), -1);
    mg_response_header_add(conn, "Cache-Control", "no-cache", -1);
    mg_response_header_add(conn, "X-Content-Type-Options", "nosniff", -1);
    // Everything the page loads comes from this server (no CDN).
    mg_response_header_add(conn, "Content-Security-Policy",
                           "default-src 'self'; img-src 'self' data: blob:; object-src 'none'", -1);
    mg_response_header_send(conn);
    if (method == "GET") mg_write(conn, asset.data, asset.size);
    return 200;
  }
  return SendError(conn, grpc::StatusCode::NOT_FOUND,
                   absl::StrCat("no such path: ", uri,
                                " (the console is at /, the JSON API is POST /v1/<Method>)"),
                   /*close=*/true);
}

int HttpGateway::ServeEvents(mg_connection* conn) {
  const mg_request_info* request = mg_get_request_info(conn);
  if (absl::string_view(request->request_method) != "GET") {
    return SendError(conn, grpc::StatusCode::UNIMPLEMENTED,
                     absl::StrCat(request->request_method, " ", kEventsPath,
                                  ": the event stream is a GET (Server-Sent Events)"),
                     /*close=*/true, /*http_status=*/405);
  }
  char map_id[256] = {};
  const char* query = request->query_string != nullptr ? request->query_string : "";
  if (mg_get_var(query, std::strlen(query), "map_id", map_id, sizeof(map_id)) <= 0) {
    return SendError(conn, grpc::StatusCode::INVALID_ARGUMENT,
                     absl::StrCat("GET ", kEventsPath, " needs ?map_id=<the map's id>"),
                     /*close=*/true);
  }
  // The caller must be able to read the map (token, tenant): gRPC decides.
  v1::GetMapRequest get;
  get.set_map_id(map_id);
  v1::GetMapResponse map;
  const pb::MethodDescriptor* get_map =
      pb::DescriptorPool::generated_pool()
          ->FindServiceByName(v1::CoveragePlanner::service_full_name())
          ->FindMethodByName("GetMap");
  if (grpc::Status s = Invoke(conn, *get_map, get, &map); !s.ok()) {
    return SendError(conn, s.error_code(), s.error_message(), /*close=*/true);
  }
  std::shared_ptr<LiveEvents::Subscription> events =
      live_ != nullptr ? live_->Subscribe(map_id) : nullptr;
  if (events == nullptr) {
    return SendError(conn, grpc::StatusCode::UNAVAILABLE,
                     "the server holds as many live event streams as it allows; try again later",
                     /*close=*/true);
  }
  mg_printf(conn,
            "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
            "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n");
  std::string out = absl::StrCat(": live events of map ", map_id, "\n\n");
  while (mg_write(conn, out.data(), out.size()) > 0) {
    // A comment every few seconds at the least: a client gone is found by
    // the failed write.
    LiveEvents::Batch batch = events->Next(absl::Seconds(5));
    if (batch.closed) break;
    out.clear();
    if (batch.dropped > 0) {
      absl::StrAppend(&out, ": ", batch.dropped, " events dropped (this client fell behind)\n\n");
    }
    for (const std::string& e : batch.events) absl::StrAppend(&out, "data: ", e, "\n\n");
    if (out.empty()) out = ":\n\n";
  }
  return 200;
}

grpc::Status HttpGateway::Invoke(mg_connection* conn, const pb::MethodDescriptor& method,
                                 const pb::Message& request, pb::Message* response) {
  grpc::ClientContext context;
  if (const char* authorization = mg_get_header(conn, "Authorization")) {
    if (!PrintableAscii(authorization)) {
      return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                          "the Authorization header holds bytes other than printable ASCII");
    }
    context.AddMetadata("authorization", authorization);
  }
  if (const char* timeout = mg_get_header(conn, "Grpc-Timeout")) {
    std::chrono::nanoseconds d{};
    if (!ParseGrpcTimeout(timeout, &d)) {
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          absl::StrCat("Grpc-Timeout '", timeout,
                                       "' is not gRPC's format (up to 8 digits and a unit of H, M, "
                                       "S, m, u, n, e.g. 5S)"));
    }
    if (d != std::chrono::nanoseconds::max()) {
      context.set_deadline(std::chrono::system_clock::now() + d);
    }
  }
  const grpc::ByteBuffer request_bytes = ToByteBuffer(request);
  grpc::ByteBuffer response_bytes;
  grpc::Status status;
  absl::Notification done;
  {
    // No call starts once the gRPC server shuts down (gRPC 1.51's in-process
    // transport must not see a new call then); a started one is its to end.
    absl::ReaderMutexLock calls(&calls_mu_);
    if (closing_) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
    stub_->UnaryCall(&context, absl::StrCat("/", method.service()->full_name(), "/", method.name()),
                     grpc::StubOptions(), &request_bytes, &response_bytes, [&](grpc::Status s) {
                       status = std::move(s);
                       done.Notify();
                     });
  }
  done.WaitForNotification();
  if (!status.ok()) return status;
  if (!FromByteBuffer(response_bytes, response)) {
    return grpc::Status(
        grpc::StatusCode::INTERNAL,
        absl::StrCat("the server's ", method.output_type()->full_name(), " did not parse"));
  }
  return grpc::Status::OK;
}

int HttpGateway::Call(mg_connection* conn, const pb::MethodDescriptor& method,
                      const std::string& body) {
  pb::MessageFactory* factory = pb::MessageFactory::generated_factory();
  std::unique_ptr<pb::Message> request(factory->GetPrototype(method.input_type())->New());
  pb::util::JsonParseOptions parse;
  parse.ignore_unknown_fields = false;
  const std::string& json = body.empty() ? kEmptyObject : body;
  if (const auto parsed = pb::util::JsonStringToMessage(json, request.get(), parse); !parsed.ok()) {
    return SendError(conn, grpc::StatusCode::INVALID_ARGUMENT,
                     absl::StrCat("the body is not a ", method.input_type()->full_name(),
                                  " in protobuf's JSON mapping: ", parsed.message().as_string()));
  }
  std::unique_ptr<pb::Message> response(factory->GetPrototype(method.output_type())->New());
  const grpc::Status status = Invoke(conn, method, *request, response.get());
  if (!status.ok()) {
    return SendError(conn, status.error_code(), status.error_message(),
                     /*close=*/status.error_code() == grpc::StatusCode::UNAVAILABLE);
  }
  pb::util::JsonPrintOptions print;
  print.always_print_primitive_fields = true;
  std::string out;
  if (const auto printed = pb::util::MessageToJsonString(*response, &out, print); !printed.ok()) {
    return SendError(
        conn, grpc::StatusCode::INTERNAL,
        absl::StrCat("the reply did not print as JSON: ", printed.message().as_string()));
  }
  SendBody(conn, 200, out, /*close=*/false);
  return 200;
}

}  // namespace covplan
