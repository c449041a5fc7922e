#include "server/solve_call.h"

#include <memory>
#include <utility>

#include "absl/time/clock.h"

namespace covplan {

grpc::ServerUnaryReactor* ServeSolve(CallGate* gate, SolveAdmission* admission,
                                     grpc::CallbackServerContext* context, const char* method,
                                     const google::protobuf::Message& request,
                                     const SolveAdmit& admit, SolveWork work) {
  auto* reactor = new CancellableReactor();
  CallInfo call;
  if (!gate->Open(context, method, reactor, request, WhileDraining::kRefuse, &call)) {
    return reactor;
  }
  if (absl::Status admitted = admit(call); !admitted.ok()) {
    gate->Finish(reactor, call, admitted);
    return reactor;
  }
  struct Outcome {
    absl::Status status;
    std::string detail;
  };
  auto outcome = std::make_shared<Outcome>();
  SolveAdmission::Task task;
  task.solve = [admission, reactor, call, outcome, work = std::move(work)] {
    admission->UpdateQueueGauge();
    outcome->status = work(call, reactor->cancel(), &outcome->detail);
  };
  task.reply = [gate, admission, reactor, call, outcome] {
    gate->Finish(reactor, call, outcome->status, outcome->status.ok() ? outcome->detail : "");
    admission->TrimMemoryIfIdle(absl::Now() - call.start);
  };
  task.cut_short = reactor->cancel();
  task.tenant_tag = call.tenant_tag;
  const bool queued = admission->Submit(std::move(task));
  admission->UpdateQueueGauge();
  if (!queued) gate->Finish(reactor, call, admission->Full());
  return reactor;
}

}  // namespace covplan
