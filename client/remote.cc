#include "client/remote.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/support/proto_buffer_reader.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/common/status_macros.h"

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

std::shared_ptr<grpc::Channel> ChannelFor(const Connection& connection) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(256 << 20);
  arguments.SetMaxSendMessageSize(256 << 20);
  // A server that went away is looked for again soon (gRPC's defaults wait
  // 1 s, then up to 2 minutes): a Drive session reconnecting after its
  // replica died finds the next one within its 2 s backoff.
  arguments.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  arguments.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 100);
  arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 2000);
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (connection.tls) {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = connection.ca_pem;
    options.pem_cert_chain = connection.cert_pem;
    options.pem_private_key = connection.key_pem;
    credentials = grpc::SslCredentials(options);
  }
  return grpc::CreateCustomChannel(connection.target, credentials, arguments);
}

void AddCallCredentials(const Connection& connection, grpc::ClientContext* context) {
  // Plain metadata rather than gRPC call credentials, which refuse
  // plaintext channels: a loopback server with tokens is served too.
  if (!connection.token.empty())
    context->AddMetadata("authorization", "Bearer " + connection.token);
}

struct RemotePlanner::Impl {
  Connection connection;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub;
  std::unique_ptr<grpc::GenericStub> generic;
};

namespace {

// Credentials, deadline and routing key of one call, in that order.
void PrepareCall(const Connection& connection, std::optional<absl::Duration> timeout,
                 const std::string& map_id, grpc::ClientContext* context) {
  AddCallCredentials(connection, context);
  if (timeout) context->set_deadline(absl::ToChronoTime(absl::Now() + *timeout));
  SetMapId(context, map_id);
}

// One blocking unary call of the generated stub, e.g. &Stub::Plan.
template <typename Request, typename Response>
absl::StatusOr<Response> CallUnary(const Connection& connection, v1::CoveragePlanner::Stub* stub,
                                   grpc::Status (v1::CoveragePlanner::Stub::*method)(
                                       grpc::ClientContext*, const Request&, Response*),
                                   const Request& request, std::optional<absl::Duration> timeout,
                                   const std::string& map_id) {
  grpc::ClientContext context;
  PrepareCall(connection, timeout, map_id, &context);
  Response response;
  if (absl::Status s = FromGrpc((stub->*method)(&context, request, &response)); !s.ok()) return s;
  return response;
}

// The stats of a serialised PlanResponse; every other field is skipped. A
// field that occurs more than once is merged, as protobuf parsing does.
absl::StatusOr<v1::PlanStats> StatsOfPlanReply(grpc::ByteBuffer* reply) {
  using google::protobuf::internal::WireFormatLite;
  grpc::ProtoBufferReader reader(reply);
  google::protobuf::io::CodedInputStream in(&reader);
  in.SetTotalBytesLimit(std::numeric_limits<int>::max());
  v1::PlanStats stats;
  bool ok = true;
  for (uint32_t tag = in.ReadTag(); ok && tag != 0; tag = in.ReadTag()) {
    if (WireFormatLite::GetTagFieldNumber(tag) == v1::PlanResponse::kStatsFieldNumber &&
        WireFormatLite::GetTagWireType(tag) == WireFormatLite::WIRETYPE_LENGTH_DELIMITED) {
      uint32_t length = 0;
      ok = in.ReadVarint32(&length) &&
           length <= static_cast<uint32_t>(std::numeric_limits<int>::max());
      if (!ok) break;
      const auto limit = in.PushLimit(static_cast<int>(length));
      ok = stats.MergePartialFromCodedStream(&in) && in.ConsumedEntireMessage();
      in.PopLimit(limit);
    } else {
      ok = WireFormatLite::SkipField(&in, tag);
    }
  }
  if (!ok || !in.ConsumedEntireMessage() || reader.status().error_code() != grpc::StatusCode::OK) {
    return absl::DataLossError("the server's Plan reply is not a valid covplan.v1.PlanResponse");
  }
  return stats;
}

}  // namespace

RemotePlanner::RemotePlanner(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RemotePlanner::~RemotePlanner() = default;

std::unique_ptr<RemotePlanner> RemotePlanner::Connect(const std::string& target) {
  Connection connection;
  connection.target = target;
  return Connect(connection);
}

std::unique_ptr<RemotePlanner> RemotePlanner::Connect(const Connection& connection) {
  auto impl = std::make_unique<Impl>();
  impl->connection = connection;
  impl->channel = ChannelFor(connection);
  impl->stub = v1::CoveragePlanner::NewStub(impl->channel);
  impl->generic = std::make_unique<grpc::GenericStub>(impl->channel);
  return std::unique_ptr<RemotePlanner>(new RemotePlanner(std::move(impl)));
}

absl::StatusOr<v1::PutMapResponse> RemotePlanner::PutMap(const v1::PutMapRequest& request,
                                                         absl::Duration timeout) {
  return CallUnary(impl_->connection, impl_->stub.get(), &v1::CoveragePlanner::Stub::PutMap,
                   request, timeout, ComputeMapId(request.map()));
}

absl::StatusOr<v1::PlanResponse> RemotePlanner::Plan(const v1::PlanRequest& request,
                                                     std::optional<absl::Duration> timeout) {
  return CallUnary(impl_->connection, impl_->stub.get(), &v1::CoveragePlanner::Stub::Plan, request,
                   timeout, RoutingMapId(request));
}

absl::StatusOr<v1::PlanStats> RemotePlanner::PlanStatsOnly(const v1::PlanRequest& request,
                                                           std::optional<absl::Duration> timeout) {
  grpc::ClientContext context;
  PrepareCall(impl_->connection, timeout, RoutingMapId(request), &context);
  grpc::ByteBuffer sent, reply;
  bool own = false;
  if (!grpc::SerializationTraits<v1::PlanRequest>::Serialize(request, &sent, &own).ok()) {
    return absl::InvalidArgumentError("could not serialise the PlanRequest");
  }
  // Waited for on this thread, as the generated blocking stubs do (a
  // callback would hand every reply over from another thread).
  grpc::CompletionQueue queue;
  std::unique_ptr<grpc::GenericClientAsyncResponseReader> call =
      impl_->generic->PrepareUnaryCall(&context, "/covplan.v1.CoveragePlanner/Plan", sent, &queue);
  call->StartCall();
  grpc::Status status;
  call->Finish(&reply, &status, &queue);
  void* tag = nullptr;
  bool ok = false;
  const bool completed = queue.Next(&tag, &ok) && ok;
  queue.Shutdown();  // drained before it is destroyed, on every path
  for (void* t = nullptr; queue.Next(&t, &ok);) {
  }
  if (!completed) return absl::InternalError("the Plan call did not complete");
  if (absl::Status s = FromGrpc(status); !s.ok()) return s;
  return StatsOfPlanReply(&reply);
}

absl::StatusOr<v1::ReplanResponse> RemotePlanner::Replan(const v1::ReplanRequest& request,
                                                         std::optional<absl::Duration> timeout,
                                                         const std::string& map_id) {
  // A replan by plan_id names no map; the caller passes the map id when it
  // has it (the plan's map_id), otherwise the router picks any replica and
  // the plan is found through the shared store.
  return CallUnary(impl_->connection, impl_->stub.get(), &v1::CoveragePlanner::Stub::Replan,
                   request, timeout,
                   request.has_plan() ? RoutingMapId(request.plan().request()) : map_id);
}

std::string ServerError(const std::string& target, const absl::Status& status) {
  return absl::StrCat("server ", target, " replied ", absl::StatusCodeToString(status.code()), ": ",
                      status.message());
}

absl::StatusOr<v1::PlanFleetResponse> RemotePlanner::PlanFleet(
    const v1::PlanFleetRequest& request, std::optional<absl::Duration> timeout) {
  return CallUnary(impl_->connection, impl_->stub.get(), &v1::CoveragePlanner::Stub::PlanFleet,
                   request, timeout, RoutingMapId(request.plan()));
}

absl::StatusOr<v1::ReplanResponse> RemotePlanner::Resume(const v1::ResumeRequest& request,
                                                         std::optional<absl::Duration> timeout) {
  return CallUnary(impl_->connection, impl_->stub.get(), &v1::CoveragePlanner::Stub::Resume,
                   request, timeout, /*map_id=*/"");
}

struct RemotePlanner::DriveSession::Stream {
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientReaderWriter<v1::DriveRequest, v1::DriveEvent>> rw;
};

RemotePlanner::DriveSession::DriveSession(Impl* owner, const v1::DriveRequest& first,
                                          const std::string& map_id)
    : owner_(owner), first_(first), map_id_(map_id) {}

RemotePlanner::DriveSession::~DriveSession() {
  if (!closed_ && stream_ != nullptr) {
    stream_->context.TryCancel();
    stream_->rw->Finish().ok();
  }
}

absl::StatusOr<std::unique_ptr<RemotePlanner::DriveSession>> RemotePlanner::Drive(
    const v1::DriveRequest& first, const std::string& map_id) {
  std::unique_ptr<DriveSession> session(new DriveSession(impl_.get(), first, map_id));
  RETURN_IF_ERROR(session->Open(first));
  // The first message's obstacles are replanned once; a reopened session
  // sends only where the robot is.
  session->first_.clear_obstacles();
  return session;
}

absl::Status RemotePlanner::DriveSession::Open(const v1::DriveRequest& first) {
  auto stream = std::make_unique<Stream>();
  AddCallCredentials(owner_->connection, &stream->context);
  SetMapId(&stream->context, map_id_);
  stream->rw = owner_->stub->Drive(&stream->context);
  stream_ = std::move(stream);
  closed_ = false;
  v1::DriveEvent event;
  if (!stream_->rw->Write(first) || !stream_->rw->Read(&event)) return Broken();
  if (!event.has_ready()) {
    stream_->context.TryCancel();
    Broken().IgnoreError();
    return absl::InternalError("the drive session's first event is not `ready`");
  }
  ready_ = event.ready();
  return absl::OkStatus();
}

absl::Status RemotePlanner::DriveSession::Broken() {
  closed_ = true;
  v1::DriveEvent rest;  // a failed Write: the call is over, the reads end at once
  while (stream_->rw->Read(&rest)) {
  }
  const absl::Status s = FromGrpc(stream_->rw->Finish());
  // The server ended the call itself (not a broken link): nothing to retry.
  return s.ok() ? absl::AbortedError("the server ended the drive session") : s;
}

namespace {

// A stream that broke on the way rather than one a server ended: UNAVAILABLE
// (the replica died or drains, the link dropped) or UNKNOWN (no status
// reached the client: a proxy such as HAProxy ended the stream when its
// replica died, "No status received"; covplan servers send no UNKNOWN).
bool LinkBroke(const absl::Status& status) {
  return absl::IsUnavailable(status) || absl::IsUnknown(status);
}

}  // namespace

absl::Status RemotePlanner::DriveSession::Reconnect(absl::Status broken) {
  const absl::Time start = absl::Now();
  // Each wait jittered by +-20 %, so a fleet whose replica died does not
  // come back in lockstep.
  std::minstd_rand jitter(static_cast<uint32_t>(reinterpret_cast<uintptr_t>(this) >> 4) ^
                          static_cast<uint32_t>(absl::ToUnixMicros(start)));
  absl::Duration backoff = absl::Milliseconds(100);
  // A reopened stream may also be refused as busy (the survivors of a dead
  // replica take its whole fleet at once: RESOURCE_EXHAUSTED from admission
  // or a tenant quota): waited out like a broken link.
  while (LinkBroke(broken) || absl::IsResourceExhausted(broken)) {
    const absl::Duration wait = backoff * std::uniform_real_distribution<double>(0.8, 1.2)(jitter);
    if (absl::Now() - start + wait > kReconnectBudget) {
      return absl::UnavailableError(
          absl::StrCat("the drive session broke and no server took it back within ",
                       absl::FormatDuration(kReconnectBudget), ": ", broken.message()));
    }
    // Until the channel is connected again (asking it to try), or after the
    // wait. Connected already (a server that answered UNAVAILABLE, e.g. one
    // draining): the whole wait.
    const absl::Time wake = absl::Now() + wait;
    if (owner_->channel->GetState(/*try_to_connect=*/false) == GRPC_CHANNEL_READY ||
        !owner_->channel->WaitForConnected(absl::ToChronoTime(wake))) {
      absl::SleepFor(wake - absl::Now());
    }
    backoff = std::min(2 * backoff, absl::Seconds(1));
    broken = Open(first_);
    if (broken.ok()) {
      reconnect_s_.push_back(absl::ToDoubleSeconds(absl::Now() - start));
      return absl::OkStatus();
    }
  }
  return broken;
}

void RemotePlanner::DriveSession::Remember(const v1::DriveRequest& request) {
  if (request.has_progress()) {
    *first_.mutable_progress() = request.progress();
    // The progress refers to the plan the request names.
    if (request.plan_ref_case() == v1::DriveRequest::kPlanId) first_.set_plan_id(request.plan_id());
  }
}

absl::StatusOr<v1::DriveEvent> RemotePlanner::DriveSession::Exchange(
    const v1::DriveRequest& request) {
  if (!stream_->rw->Write(request)) return Broken();
  v1::DriveEvent event;
  while (stream_->rw->Read(&event)) {
    if (event.sequence() == request.sequence()) return event;
  }
  return Broken();
}

absl::StatusOr<v1::DriveEvent> RemotePlanner::DriveSession::Observe(
    const v1::DriveRequest& request) {
  if (closed_) return absl::FailedPreconditionError("the drive session is closed");
  Remember(request);
  absl::StatusOr<v1::DriveEvent> event = Exchange(request);
  // Unanswered: once more on a new stream, a few times at most (a request
  // that took its server down each time would otherwise loop forever).
  for (int resent = 0; !event.ok() && LinkBroke(event.status()); ++resent) {
    if (resent == kMaxResends) {
      return absl::UnavailableError(absl::StrCat(
          "the drive session broke ", kMaxResends + 1,
          " times while this observation waited for its answer: ", event.status().message()));
    }
    RETURN_IF_ERROR(Reconnect(event.status()));
    event = Exchange(request);
  }
  if (!event.ok()) return event.status();
  // The robot drives the new plan from here: a reopened session starts on it
  // (the server stored it before it sent it).
  if (event->has_replan() && !event->replan().plan().plan_id().empty()) {
    first_.set_plan_id(event->replan().plan().plan_id());
    first_.clear_progress();
  }
  return event;
}

absl::Status RemotePlanner::DriveSession::Report(const v1::DriveRequest& request) {
  if (closed_) return absl::FailedPreconditionError("the drive session is closed");
  Remember(request);
  if (stream_->rw->Write(request)) return absl::OkStatus();
  const absl::Status broken = Broken();
  if (!LinkBroke(broken)) return broken;
  // The reopened session starts from this report's progress: nothing to resend.
  return Reconnect(broken);
}

absl::Status RemotePlanner::DriveSession::Close() {
  if (closed_) return absl::OkStatus();
  closed_ = true;
  stream_->rw->WritesDone();
  v1::DriveEvent event;
  while (stream_->rw->Read(&event)) {
  }
  return FromGrpc(stream_->rw->Finish());
}

}  // namespace covplan
