#include "server/replan_handlers.h"

#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"

namespace covplan {

grpc::ServerUnaryReactor* ReplanHandlers::ServeSolve(grpc::CallbackServerContext* context,
                                                     const char* method,
                                                     const google::protobuf::Message& request,
                                                     Work work) {
  auto* reactor = new CancellableReactor();
  CallInfo call;
  if (!gate_->Open(context, method, reactor, request, WhileDraining::kRefuse, &call)) {
    return reactor;
  }
  if (absl::Status admitted = admission_->Admit(); !admitted.ok()) {
    gate_->Finish(reactor, call, admitted);
    return reactor;
  }
  struct Outcome {
    absl::Status status;
    std::string detail;
  };
  auto outcome = std::make_shared<Outcome>();
  SolveAdmission::Task task;
  task.solve = [reactor, call, outcome, work = std::move(work)] {
    outcome->status = work(call, reactor->cancel(), &outcome->detail);
  };
  task.reply = [this, reactor, call, outcome] {
    gate_->Finish(reactor, call, outcome->status, outcome->status.ok() ? outcome->detail : "");
    admission_->TrimMemoryIfIdle(absl::Now() - call.start);
  };
  task.cut_short = reactor->cancel();
  if (!admission_->Submit(std::move(task))) gate_->Finish(reactor, call, WorkQueueFull());
  return reactor;
}

grpc::ServerUnaryReactor* ReplanHandlers::Replan(grpc::CallbackServerContext* context,
                                                 const v1::ReplanRequest* request,
                                                 v1::ReplanResponse* response) {
  return ServeSolve(context, "Replan", *request,
                    [this, request, response](const CallInfo& call, const StopToken& cancel,
                                              std::string* detail) {
                      absl::Status status = work_->RunReplan(call, *request, cancel, response);
                      if (status.ok()) *detail = ReplanDetail(*response);
                      return status;
                    });
}

grpc::ServerUnaryReactor* ReplanHandlers::Resume(grpc::CallbackServerContext* context,
                                                 const v1::ResumeRequest* request,
                                                 v1::ReplanResponse* response) {
  return ServeSolve(context, "Resume", *request,
                    [this, request, response](const CallInfo& call, const StopToken& cancel,
                                              std::string* detail) {
                      absl::Status status = work_->RunResume(call, *request, cancel, response);
                      if (status.ok()) {
                        *detail = absl::StrCat(ReplanDetail(*response),
                                               " from=", response->replan().progress_source());
                      }
                      return status;
                    });
}

}  // namespace covplan
