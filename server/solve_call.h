// One unary solve, the same for every RPC that plans on the solve pool
// (Replan, Resume, PlanFleet, UpdateMission): the gate opens the call,
// `admit` takes a slot (SolveAdmission::Admit or AdmitPlan), `work` runs on a
// worker with the call's cancellation, and the gate finishes the call after
// the slot is released, logging the detail `work` set when it succeeded.
//
//   return ServeSolve(gate_, admission_, context, "Replan", *request,
//                     [this](const CallInfo& call) { return admission_->Admit(call); },
//                     [this, request, response](const CallInfo& call, const StopToken& cancel,
//                                               std::string* detail) { ... });
//
// Thread-safety: as the gate and the admission.
#ifndef COVPLAN_SERVER_SOLVE_CALL_H_
#define COVPLAN_SERVER_SOLVE_CALL_H_

#include <grpcpp/grpcpp.h>

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "google/protobuf/message.h"
#include "planner/common/stop_token.h"
#include "server/admission.h"
#include "server/call_gate.h"

namespace covplan {

using SolveAdmit = std::function<absl::Status(const CallInfo&)>;
using SolveWork =
    std::function<absl::Status(const CallInfo&, const StopToken& cancel, std::string* detail)>;

grpc::ServerUnaryReactor* ServeSolve(CallGate* gate, SolveAdmission* admission,
                                     grpc::CallbackServerContext* context, const char* method,
                                     const google::protobuf::Message& request,
                                     const SolveAdmit& admit, SolveWork work);

}  // namespace covplan

#endif  // COVPLAN_SERVER_SOLVE_CALL_H_
