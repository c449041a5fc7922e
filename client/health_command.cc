#include "client/health_command.h"

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "client/args.h"
#include "client/remote.h"
#include "google/protobuf/io/coded_stream.h"
#include "google/protobuf/io/zero_copy_stream_impl_lite.h"
#include "google/protobuf/wire_format_lite.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

constexpr char kUsage[] =
    "usage: covplan health --server HOST:PORT [--service NAME] [--timeout-ms T]\n"
    "                     [--tls-ca PEM] [--tls-cert PEM --tls-key PEM] [--token T | --token-file "
    "F]\n"
    "Prints the grpc.health.v1 status (SERVING, NOT_SERVING, ...); exit 0 only for SERVING.\n";

// grpc.health.v1.HealthCheckRequest { string service = 1; } by hand: the
// health proto's generated code is not part of Debian's libgrpc++-dev.
std::string EncodeRequest(const std::string& service) {
  std::string out;
  if (service.empty()) return out;
  google::protobuf::io::StringOutputStream stream(&out);
  google::protobuf::io::CodedOutputStream coded(&stream);
  coded.WriteTag((1 << 3) | 2);
  coded.WriteVarint32(static_cast<uint32_t>(service.size()));
  coded.WriteString(service);
  return out;
}

// HealthCheckResponse { ServingStatus status = 1; } -> the enum value.
int DecodeStatus(const std::string& bytes) {
  google::protobuf::io::CodedInputStream in(reinterpret_cast<const uint8_t*>(bytes.data()),
                                            static_cast<int>(bytes.size()));
  int status = 0;  // UNKNOWN
  for (uint32_t tag = in.ReadTag(); tag != 0; tag = in.ReadTag()) {
    uint64_t value = 0;
    if (tag == (1 << 3) && in.ReadVarint64(&value)) {
      status = static_cast<int>(value);
    } else if (!google::protobuf::internal::WireFormatLite::SkipField(&in, tag)) {
      break;
    }
  }
  return status;
}

const char* StatusName(int status) {
  switch (status) {
    case 1:
      return "SERVING";
    case 2:
      return "NOT_SERVING";
    case 3:
      return "SERVICE_UNKNOWN";
    default:
      return "UNKNOWN";
  }
}

absl::Status Run(const std::vector<std::string>& args) {
  ASSIGN_OR_RETURN(ParsedArgs a,
                   ParseArgs(args, WithConnectionFlags({"server", "service", "timeout-ms"}), {}));
  if (!a.Get("server")) return absl::InvalidArgumentError("--server HOST:PORT is required");
  ASSIGN_OR_RETURN(std::optional<int64_t> timeout_ms, a.GetInt("timeout-ms"));
  const int64_t timeout = timeout_ms.value_or(2000);
  if (timeout <= 0) return absl::InvalidArgumentError("--timeout-ms must be positive");
  ASSIGN_OR_RETURN(Connection connection, ConnectionFromArgs(a, *a.Get("server")));
  grpc::GenericStub stub(ChannelFor(connection));
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  AddCallCredentials(connection, &context);  // health is open; harmless
  const auto deadline = std::chrono::system_clock::now() + std::chrono::milliseconds(timeout);
  context.set_deadline(deadline);
  const std::string request = EncodeRequest(a.Get("service").value_or(""));
  grpc::Slice slice(request);
  grpc::ByteBuffer buffer(&slice, 1);
  auto call = stub.PrepareUnaryCall(&context, "/grpc.health.v1.Health/Check", buffer, &cq);
  call->StartCall();
  grpc::ByteBuffer reply;
  grpc::Status status;
  int tag = 0;
  call->Finish(&reply, &status, &tag);
  void* got = nullptr;
  bool ok = false;
  if (cq.AsyncNext(&got, &ok, deadline + std::chrono::seconds(1)) !=
          grpc::CompletionQueue::GOT_EVENT ||
      got != &tag) {
    return absl::DeadlineExceededError("health check did not complete");
  }
  if (!status.ok()) {
    return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                        absl::StrCat("health check failed: ", status.error_message()));
  }
  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (reply.Dump(&slices).ok()) {
    for (const grpc::Slice& s : slices)
      bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  }
  const int serving = DecodeStatus(bytes);
  std::printf("%s\n", StatusName(serving));
  if (serving != 1)
    return absl::UnavailableError(absl::StrCat("server reports ", StatusName(serving)));
  return absl::OkStatus();
}

}  // namespace

int RunHealthCommand(const std::vector<std::string>& args) {
  return RunSubcommand("health", kUsage, args, &Run);
}

}  // namespace covplan
