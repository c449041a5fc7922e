#include "client/remote.h"

#include <grpcpp/grpcpp.h>

#include "api/convert.h"
#include "covplan/v1/covplan.grpc.pb.h"

namespace covplan {
namespace {

// The routing key a map-affine router hashes on (see docs/deploy.md). An
// inline map sends its content hash, the id the server would give it, so a
// router sends it where PutMap(map) would have gone.
constexpr char kMapIdHeader[] = "x-covplan-map-id";

void SetMapId(grpc::ClientContext* context, const std::string& map_id) {
  if (!map_id.empty()) context->AddMetadata(kMapIdHeader, map_id);
}

std::string RoutingMapId(const v1::PlanRequest& request) {
  if (request.has_map()) return ComputeMapId(request.map());
  return request.map_id();
}

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
  SetMapId(&context, ComputeMapId(request.map()));
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
  SetMapId(&context, RoutingMapId(request));
  v1::PlanResponse response;
  if (absl::Status s = FromGrpc(impl_->stub->Plan(&context, request, &response)); !s.ok()) {
    return s;
  }
  return response;
}

absl::StatusOr<v1::ReplanResponse> RemotePlanner::Replan(const v1::ReplanRequest& request,
                                                         std::optional<absl::Duration> timeout,
                                                         const std::string& map_id) {
  grpc::ClientContext context;
  if (timeout) context.set_deadline(absl::ToChronoTime(absl::Now() + *timeout));
  // A replan by plan_id names no map; the caller passes the map id when it
  // has it (the plan's map_id), otherwise the router picks any replica and
  // the plan is found through the shared store.
  if (request.has_plan()) {
    SetMapId(&context, RoutingMapId(request.plan().request()));
  } else {
    SetMapId(&context, map_id);
  }
  v1::ReplanResponse response;
  if (absl::Status s = FromGrpc(impl_->stub->Replan(&context, request, &response)); !s.ok()) {
    return s;
  }
  return response;
}

}  // namespace covplan
