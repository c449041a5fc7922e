#include "server/call_gate.h"

#include <chrono>
#include <random>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/strings/string_view.h"
#include "server/grpc_status.h"
#include "server/log.h"
#include "server/request_limits.h"

namespace covplan {
namespace {

absl::Time DeadlineOf(const grpc::CallbackServerContext& context) {
  const auto deadline = context.deadline();
  // gRPC reports "no deadline" as a far-future time point.
  if (deadline >= std::chrono::system_clock::now() + std::chrono::hours(24 * 365)) {
    return absl::InfiniteFuture();
  }
  return absl::FromChrono(deadline);
}

}  // namespace

CallGate::CallGate(ServerMetrics* metrics, const TenantTokens* tokens)
    : metrics_(metrics), tokens_(tokens), id_salt_(std::random_device{}()) {}

CallInfo CallGate::Start(grpc::CallbackServerContext* context, const char* method) {
  active_calls_.fetch_add(1);
  return Begin(context, method);
}

CallInfo CallGate::StartStream(grpc::CallbackServerContext* context, const char* method) {
  return Begin(context, method);
}

CallInfo CallGate::Begin(grpc::CallbackServerContext* context, const char* method) {
  CallInfo call;
  call.method = method;
  call.start = absl::Now();
  call.deadline = DeadlineOf(*context);
  const auto& metadata = context->client_metadata();
  if (auto it = metadata.find("x-request-id"); it != metadata.end() && it->second.size() <= 64) {
    call.request_id.assign(it->second.data(), it->second.size());
    for (char& c : call.request_id) {
      if (c <= ' ' || c > '~' || c == '"') c = '_';
    }
  }
  if (call.request_id.empty()) {
    call.request_id = absl::StrFormat("%08x-%06x", static_cast<uint32_t>(id_salt_),
                                      next_id_.fetch_add(1, std::memory_order_relaxed));
  }
  context->AddInitialMetadata("x-request-id", call.request_id);
  if (tokens_ != nullptr) {
    auto it = metadata.find("authorization");
    const absl::string_view authorization =
        it == metadata.end() ? absl::string_view()
                             : absl::string_view(it->second.data(), it->second.size());
    absl::StatusOr<std::string> tenant = tokens_->Authenticate(authorization);
    if (tenant.ok()) {
      call.tenant_tag = TenantTag(*tenant);
      call.tenant = *std::move(tenant);
    } else {
      call.auth = tenant.status();
      call.tenant = "unauthenticated";
    }
  }
  return call;
}

bool CallGate::Admit(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                     const google::protobuf::Message& request, WhileDraining drain) {
  if (!call.auth.ok()) {
    Finish(reactor, call, call.auth);
    return false;
  }
  if (drain == WhileDraining::kRefuse && draining()) {
    Finish(reactor, call, absl::UnavailableError("server is shutting down"));
    return false;
  }
  if (absl::Status s = CheckRequestStrings(request); !s.ok()) {
    Finish(reactor, call, s);
    return false;
  }
  return true;
}

bool CallGate::Open(grpc::CallbackServerContext* context, const char* method,
                    grpc::ServerUnaryReactor* reactor, const google::protobuf::Message& request,
                    WhileDraining drain, CallInfo* call) {
  *call = Start(context, method);
  return Admit(reactor, *call, request, drain);
}

void CallGate::Finish(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
                      const absl::Status& status, const std::string& detail) {
  Record(call, status, detail);
  reactor->Finish(ToGrpc(status));
  active_calls_.fetch_sub(1);
}

void CallGate::Record(const CallInfo& call, const absl::Status& status, const std::string& detail) {
  const absl::Time now = absl::Now();
  const double seconds = absl::ToDoubleSeconds(now - call.start);
  metrics_->RecordRequest(call.method, CodeName(status), seconds, call.tenant);
  const bool late = now > call.deadline;
  LogLine(status.ok() ? "info" : "warn", "request finished",
          {{"req", call.request_id},
           {"tenant", call.tenant.empty() ? "-" : call.tenant},
           {"method", call.method},
           {"code", CodeName(status)},
           {"ms", absl::StrFormat("%.1f", seconds * 1e3)},
           {"late", late ? "true" : "false"},
           {"detail", BoundedMessage(status.ok() ? detail : std::string(status.message()))}});
}

}  // namespace covplan
