// Test-only probes of a running server without extra generated code: the
// gRPC health check and reflection's service list via the generic stub
// (messages hand-encoded; the protos are tiny and stable), and an HTTP GET
// for /metrics.
//
//   absl::StatusOr<int> status = HealthStatus(channel, "");  // 1 = SERVING
//   absl::StatusOr<std::string> reply = RawUnaryCall(channel, "/pkg.Svc/Method", bytes);
//   absl::StatusOr<std::vector<std::string>> names = ReflectionServices(channel);
//   absl::StatusOr<std::string> body = HttpGet(9464, "/metrics");
//
// Thread-safety: stateless; each call uses its own completion queue/socket.
#ifndef COVPLAN_TESTS_SERVER_GRPC_PROBE_H_
#define COVPLAN_TESTS_SERVER_GRPC_PROBE_H_

#include <grpcpp/channel.h>
#include <grpcpp/support/byte_buffer.h>

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"

namespace covplan::testing {

// The bytes of a ByteBuffer, flattened (empty if it cannot be read).
std::string FromBuffer(const grpc::ByteBuffer& buffer);

// One unary call of `method` ("/package.Service/Method") with `request` as
// its raw bytes (and `authorization` metadata unless empty); the reply's
// bytes, or the call's status (code and message).
absl::StatusOr<std::string> RawUnaryCall(const std::shared_ptr<grpc::Channel>& channel,
                                         const std::string& method, const std::string& request,
                                         const std::string& authorization = "");

// grpc.health.v1 ServingStatus: 0 UNKNOWN, 1 SERVING, 2 NOT_SERVING.
absl::StatusOr<int> HealthStatus(const std::shared_ptr<grpc::Channel>& channel,
                                 const std::string& service);

absl::StatusOr<std::vector<std::string>> ReflectionServices(
    const std::shared_ptr<grpc::Channel>& channel);

// GET http://127.0.0.1:port/path; returns the body of a 200 reply.
absl::StatusOr<std::string> HttpGet(int port, const std::string& path);

// One HTTP/1.0 exchange with 127.0.0.1:port: `method` `path` with the given
// header lines ("Name: value") and body; the reply's status, its header
// block and its body. An error only when no reply came.
struct HttpReply {
  int status = 0;
  std::string headers;
  std::string body;
};
absl::StatusOr<HttpReply> HttpRequest(int port, const std::string& method, const std::string& path,
                                      const std::vector<std::string>& headers = {},
                                      const std::string& body = "");

// An HTTP response read as it arrives (an event stream): Open sends the
// request; ReadUntil reads until `text` has arrived (true) or `timeout`.
class HttpStream {
 public:
  ~HttpStream();
  static absl::StatusOr<std::unique_ptr<HttpStream>> Open(
      int port, const std::string& path, const std::vector<std::string>& headers = {});
  bool ReadUntil(const std::string& text, absl::Duration timeout);
  // Everything read so far (headers included).
  const std::string& received() const { return received_; }

 private:
  explicit HttpStream(int fd) : fd_(fd) {}
  const int fd_;
  std::string received_;
};

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_SERVER_GRPC_PROBE_H_
