#include "tests/server/grpc_probe.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <chrono>

#include <google/protobuf/unknown_field_set.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace covplan::testing {
namespace {

grpc::ByteBuffer ToBuffer(const std::string& bytes) {
  grpc::Slice slice(bytes);
  return grpc::ByteBuffer(&slice, 1);
}

std::string LengthDelimited(int field, const std::string& value) {
  std::string out(1, static_cast<char>((field << 3) | 2));
  out += static_cast<char>(value.size());  // values here are < 128 bytes
  return out + value;
}

// Waits for `tag` on `cq` (5 s at most); false on timeout or failure.
bool Await(grpc::CompletionQueue& cq, void* tag) {
  void* got = nullptr;
  bool ok = false;
  const auto deadline = std::chrono::system_clock::now() + std::chrono::seconds(5);
  if (cq.AsyncNext(&got, &ok, deadline) != grpc::CompletionQueue::GOT_EVENT) return false;
  return ok && got == tag;
}

absl::Status FromGrpc(const grpc::Status& s) {
  return absl::Status(static_cast<absl::StatusCode>(s.error_code()), s.error_message());
}

}  // namespace

std::string FromBuffer(const grpc::ByteBuffer& buffer) {
  std::vector<grpc::Slice> slices;
  std::string out;
  if (!buffer.Dump(&slices).ok()) return out;
  for (const grpc::Slice& s : slices)
    out.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return out;
}

absl::StatusOr<std::string> RawUnaryCall(const std::shared_ptr<grpc::Channel>& channel,
                                         const std::string& method, const std::string& request,
                                         const std::string& authorization) {
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  if (!authorization.empty()) context.AddMetadata("authorization", authorization);
  auto call = stub.PrepareUnaryCall(&context, method, ToBuffer(request), &cq);
  call->StartCall();
  grpc::ByteBuffer reply;
  grpc::Status status;
  int tag = 0;
  call->Finish(&reply, &status, &tag);
  if (!Await(cq, &tag)) return absl::DeadlineExceededError(method + " did not complete");
  if (!status.ok()) return FromGrpc(status);
  return FromBuffer(reply);
}

absl::StatusOr<int> HealthStatus(const std::shared_ptr<grpc::Channel>& channel,
                                 const std::string& service) {
  const std::string request = service.empty() ? "" : LengthDelimited(1, service);
  absl::StatusOr<std::string> bytes =
      RawUnaryCall(channel, "/grpc.health.v1.Health/Check", request);
  if (!bytes.ok()) return bytes.status();
  google::protobuf::UnknownFieldSet fields;
  if (!fields.ParseFromString(*bytes)) return absl::DataLossError("bad health reply");
  for (int i = 0; i < fields.field_count(); ++i) {
    if (fields.field(i).number() == 1) return static_cast<int>(fields.field(i).varint());
  }
  return 0;  // proto3 default: UNKNOWN
}

absl::StatusOr<std::vector<std::string>> ReflectionServices(
    const std::shared_ptr<grpc::Channel>& channel) {
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  auto call = stub.PrepareCall(
      &context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &cq);
  int tags[5];
  call->StartCall(&tags[0]);
  if (!Await(cq, &tags[0])) return absl::UnavailableError("reflection call did not start");
  call->Write(ToBuffer(LengthDelimited(7, "*")), &tags[1]);  // list_services
  if (!Await(cq, &tags[1])) return absl::UnavailableError("reflection write failed");
  call->WritesDone(&tags[2]);
  if (!Await(cq, &tags[2])) return absl::UnavailableError("reflection WritesDone failed");
  grpc::ByteBuffer reply;
  call->Read(&reply, &tags[3]);
  const bool got_reply = Await(cq, &tags[3]);
  grpc::Status status;
  call->Finish(&status, &tags[4]);
  if (!Await(cq, &tags[4])) return absl::UnavailableError("reflection Finish failed");
  if (!status.ok()) return FromGrpc(status);
  if (!got_reply) return absl::DataLossError("no reflection reply");

  google::protobuf::UnknownFieldSet response;
  if (!response.ParseFromString(FromBuffer(reply))) return absl::DataLossError("bad reply");
  std::vector<std::string> names;
  for (int i = 0; i < response.field_count(); ++i) {
    if (response.field(i).number() != 6) continue;  // list_services_response
    google::protobuf::UnknownFieldSet list;
    if (!list.ParseFromString(response.field(i).length_delimited())) continue;
    for (int j = 0; j < list.field_count(); ++j) {
      if (list.field(j).number() != 1) continue;  // repeated ServiceResponse service
      google::protobuf::UnknownFieldSet entry;
      if (!entry.ParseFromString(list.field(j).length_delimited())) continue;
      for (int k = 0; k < entry.field_count(); ++k) {
        if (entry.field(k).number() == 1) names.push_back(entry.field(k).length_delimited());
      }
    }
  }
  return names;
}

absl::StatusOr<HttpReply> HttpRequest(int port, const std::string& method, const std::string& path,
                                      const std::vector<std::string>& headers,
                                      const std::string& body) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return absl::InternalError("socket failed");
  timeval timeout{30, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(fd);
    return absl::UnavailableError(absl::StrCat("cannot connect to 127.0.0.1:", port));
  }
  std::string request = absl::StrCat(method, " ", path, " HTTP/1.0\r\nHost: 127.0.0.1\r\n");
  for (const std::string& h : headers) absl::StrAppend(&request, h, "\r\n");
  bool has_length = false;
  for (const std::string& h : headers) has_length |= h.rfind("Content-Length:", 0) == 0;
  if (method != "GET" && !has_length) {
    absl::StrAppend(&request, "Content-Length: ", body.size(), "\r\n");
  }
  absl::StrAppend(&request, "\r\n", body);
  // A server may answer (413) and close before taking the whole body.
  size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  std::string reply;
  char buffer[8192];
  for (int i = 0; i < 1000000; ++i) {  // bounded; ends at EOF
    const ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    reply.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  const size_t end = reply.find("\r\n\r\n");
  HttpReply r;
  if (reply.size() < 12 || reply.compare(0, 5, "HTTP/") != 0 || end == std::string::npos ||
      !absl::SimpleAtoi(reply.substr(9, 3), &r.status)) {
    return absl::UnavailableError(absl::StrCat("no HTTP reply: '", reply.substr(0, 40), "'"));
  }
  r.headers = reply.substr(0, end);
  r.body = reply.substr(end + 4);
  return r;
}

absl::StatusOr<std::string> HttpGet(int port, const std::string& path) {
  absl::StatusOr<HttpReply> reply = HttpRequest(port, "GET", path);
  if (!reply.ok()) return reply.status();
  if (reply->status != 200) {
    return absl::UnavailableError(absl::StrCat("HTTP reply: ", reply->headers.substr(0, 40)));
  }
  return reply->body;
}

HttpStream::~HttpStream() { ::close(fd_); }

absl::StatusOr<std::unique_ptr<HttpStream>> HttpStream::Open(
    int port, const std::string& path, const std::vector<std::string>& headers) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return absl::InternalError("socket failed");
  std::unique_ptr<HttpStream> stream(new HttpStream(fd));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    return absl::UnavailableError(absl::StrCat("cannot connect to 127.0.0.1:", port));
  }
  std::string request = absl::StrCat("GET ", path, " HTTP/1.1\r\nHost: 127.0.0.1\r\n");
  for (const std::string& h : headers) absl::StrAppend(&request, h, "\r\n");
  absl::StrAppend(&request, "\r\n");
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) !=
      static_cast<ssize_t>(request.size())) {
    return absl::UnavailableError("cannot send the request");
  }
  return stream;
}

bool HttpStream::ReadUntil(const std::string& text, absl::Duration timeout) {
  const absl::Time deadline = absl::Now() + timeout;
  while (received_.find(text) == std::string::npos) {
    const absl::Duration left = deadline - absl::Now();
    if (left <= absl::ZeroDuration()) return false;
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(absl::ToInt64Milliseconds(left)) + 1) <= 0) continue;
    char buffer[8192];
    const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), 0);
    if (n <= 0) return received_.find(text) != std::string::npos;  // closed
    received_.append(buffer, static_cast<size_t>(n));
  }
  return true;
}

}  // namespace covplan::testing
