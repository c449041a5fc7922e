// The gate every CoveragePlanner call passes once: it starts the call
// (request id, deadline, the bearer token's tenant), refuses it when the
// token is bad, the server drains or a request string is over its bound,
// and at the end finishes it and records it (metrics and one log line).
// With a token file, calls without a valid token are refused before they
// get here, at the transport (server/transport_auth.h: TLS and loopback
// ports) or at the JSON API's door; the gate looks the token up again to
// learn the call's tenant, and its own refusal is the only one for a
// plaintext port beyond loopback.
// Handlers do their own work between Open and Finish and nothing else of
// the kind.
//
//   auto* reactor = new CancellableReactor();
//   CallInfo call;
//   if (!gate.Open(context, "GetPlan", reactor, *request, WhileDraining::kServe, &call))
//     return reactor;  // refused and finished
//   ...
//   gate.Finish(reactor, call, status, detail);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_CALL_GATE_H_
#define COVPLAN_SERVER_CALL_GATE_H_

#include <atomic>
#include <cstdint>
#include <string>

#include <grpcpp/grpcpp.h>

#include "absl/status/status.h"
#include "google/protobuf/message.h"
#include "planner/common/stop_token.h"
#include "server/call_info.h"
#include "server/metrics.h"
#include "server/tenant_tokens.h"

namespace covplan {

// A unary reactor whose cancellation (client gone, deadline passed) cancels
// the token the call's work polls; it deletes itself when gRPC is done.
class CancellableReactor final : public grpc::ServerUnaryReactor {
 public:
  void OnCancel() override { cancel_.Cancel(); }
  void OnDone() override { delete this; }
  const StopToken& cancel() const { return cancel_; }

 private:
  StopToken cancel_;
};

// Whether a method is refused while the server drains (calls that start new
// work) or still served (reads, deletes).
enum class WhileDraining { kRefuse, kServe };

class CallGate {
 public:
  // `tokens` (optional, outlives the gate): every call must carry a bearer
  // token of a tenant.
  CallGate(ServerMetrics* metrics, const TenantTokens* tokens);

  // Starts a unary call (counted in active_calls() until Finish): its
  // request id (the client's x-request-id, sanitised, or a new one, echoed
  // in the initial metadata), deadline and tenant.
  CallInfo Start(grpc::CallbackServerContext* context, const char* method);
  // The same for a streaming call, which is not counted (a drain does not
  // wait for sessions; it ends them).
  CallInfo StartStream(grpc::CallbackServerContext* context, const char* method);

  // The checks every call passes after Start: its token, the drain, the
  // bounds of the request's strings. False when the call was refused (and
  // finished with the reason).
  bool Admit(grpc::ServerUnaryReactor* reactor, const CallInfo& call,
             const google::protobuf::Message& request, WhileDraining drain);
  // Start and Admit.
  bool Open(grpc::CallbackServerContext* context, const char* method,
            grpc::ServerUnaryReactor* reactor, const google::protobuf::Message& request,
            WhileDraining drain, CallInfo* call);

  // Records a call's metrics and logs one line; `detail` is logged for a
  // call that succeeded, the status message for one that did not.
  void Record(const CallInfo& call, const absl::Status& status, const std::string& detail = "");
  // Finishes `reactor` with `status`, records it and ends it in active_calls().
  void Finish(grpc::ServerUnaryReactor* reactor, const CallInfo& call, const absl::Status& status,
              const std::string& detail = "");

  void StartDraining() { draining_.store(true); }
  bool draining() const { return draining_.load(); }
  // Unary calls between Start and Finish (health and reflection streams
  // are not counted, so they never hold a drain).
  int active_calls() const { return active_calls_.load(); }

 private:
  CallInfo Begin(grpc::CallbackServerContext* context, const char* method);

  ServerMetrics* const metrics_;
  const TenantTokens* const tokens_;
  const uint64_t id_salt_;
  std::atomic<uint64_t> next_id_{1};
  std::atomic<bool> draining_{false};
  std::atomic<int> active_calls_{0};
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_CALL_GATE_H_
