#include "client/remote.h"

#include <grpcpp/grpcpp.h>

#include "covplan/v1/covplan.grpc.pb.h"

namespace covplan {
namespace {

absl::Status FromGrpc(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

}  // namespace

struct RemotePlanner::Impl {
  std::unique_ptr<v1::CoveragePlanner::Stub> stub;
};

RemotePlanner::RemotePlanner(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RemotePlanner::~RemotePlanner() = default;

std::unique_ptr<RemotePlanner> RemotePlanner::Connect(const std::string& target) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(256 << 20);
  arguments.SetMaxSendMessageSize(256 << 20);
  auto impl = std::make_unique<Impl>();
  impl->stub = v1::CoveragePlanner::NewStub(
      grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), arguments));
  return std::unique_ptr<RemotePlanner>(new RemotePlanner(std::move(impl)));
}

absl::StatusOr<v1::PutMapResponse> RemotePlanner::PutMap(const v1::PutMapRequest& request,
                                                         absl::Duration timeout) {
  grpc::ClientContext context;
  context.set_deadline(absl::ToChronoTime(absl::Now() + timeout));
  v1::PutMapResponse response;
  if (absl::Status s = FromGrpc(impl_->stub->PutMap(&context, request, &response)); !s.ok()) {
    return s;
  }
  return response;
}

absl::StatusOr<v1::PlanResponse> RemotePlanner::Plan(const v1::PlanRequest& request,
                                                     std::optional<absl::Duration> timeout) {
  grpc::ClientContext context;
  if (timeout) context.set_deadline(absl::ToChronoTime(absl::Now() + *timeout));
  v1::PlanResponse response;
  if (absl::Status s = FromGrpc(impl_->stub->Plan(&context, request, &response)); !s.ok()) {
    return s;
  }
  return response;
}

absl::StatusOr<v1::ReplanResponse> RemotePlanner::Replan(const v1::ReplanRequest& request,
                                                         std::optional<absl::Duration> timeout) {
  grpc::ClientContext context;
  if (timeout) context.set_deadline(absl::ToChronoTime(absl::Now() + *timeout));
  v1::ReplanResponse response;
  if (absl::Status s = FromGrpc(impl_->stub->Replan(&context, request, &response)); !s.ok()) {
    return s;
  }
  return response;
}

}  // namespace covplan
