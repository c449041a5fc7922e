// The unary calls that continue a plan: Replan and Resume. Each passes the
// CallGate, is admitted to the solve pool under the same bound as Plan
// (server/admission.h), runs its ReplanWork on a worker (cut short by the
// drain's end like a Plan) and replies from there.
//
//   ReplanHandlers replans(&gate, &admission, &work);
//   return replans.Replan(context, request, response);
//
// Thread-safety: handlers are called concurrently by gRPC; they share only
// thread-safe parts.
#ifndef COVPLAN_SERVER_REPLAN_HANDLERS_H_
#define COVPLAN_SERVER_REPLAN_HANDLERS_H_

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "google/protobuf/message.h"
#include "planner/common/stop_token.h"
#include "server/admission.h"
#include "server/call_gate.h"
#include "server/replan_work.h"
#include "server/solve_call.h"

namespace covplan {

class ReplanHandlers {
 public:
  // Every pointer outlives this.
  ReplanHandlers(CallGate* gate, SolveAdmission* admission, ReplanWork* work)
      : gate_(gate), admission_(admission), work_(work) {}

  grpc::ServerUnaryReactor* Replan(grpc::CallbackServerContext* context,
                                   const v1::ReplanRequest* request, v1::ReplanResponse* response);
  grpc::ServerUnaryReactor* Resume(grpc::CallbackServerContext* context,
                                   const v1::ResumeRequest* request, v1::ReplanResponse* response);

 private:
  // A unary solve (server/solve_call.h) admitted with a plain slot.
  grpc::ServerUnaryReactor* ServeReplanSolve(grpc::CallbackServerContext* context,
                                             const char* method,
                                             const google::protobuf::Message& request,
                                             SolveWork work);

  CallGate* const gate_;
  SolveAdmission* const admission_;
  ReplanWork* const work_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_REPLAN_HANDLERS_H_
