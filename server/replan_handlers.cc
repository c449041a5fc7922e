#include "server/replan_handlers.h"

#include "server/solve_call.h"

#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"

namespace covplan {

grpc::ServerUnaryReactor* ReplanHandlers::ServeReplanSolve(grpc::CallbackServerContext* context,
                                                           const char* method,
                                                           const google::protobuf::Message& request,
                                                           SolveWork work) {
  return ServeSolve(
      gate_, admission_, context, method, request,
      [this](const CallInfo& call) { return admission_->Admit(call); }, std::move(work));
}

grpc::ServerUnaryReactor* ReplanHandlers::Replan(grpc::CallbackServerContext* context,
                                                 const v1::ReplanRequest* request,
                                                 v1::ReplanResponse* response) {
  return ServeReplanSolve(context, "Replan", *request,
                          [this, request, response](const CallInfo& call, const StopToken& cancel,
                                                    std::string* detail) {
                            absl::Status status =
                                work_->RunReplan(call, *request, cancel, response);
                            if (status.ok()) *detail = ReplanDetail(*response);
                            return status;
                          });
}

grpc::ServerUnaryReactor* ReplanHandlers::Resume(grpc::CallbackServerContext* context,
                                                 const v1::ResumeRequest* request,
                                                 v1::ReplanResponse* response) {
  return ServeReplanSolve(
      context, "Resume", *request,
      [this, request, response](const CallInfo& call, const StopToken& cancel,
                                std::string* detail) {
        absl::Status status = work_->RunResume(call, *request, cancel, response);
        if (status.ok()) {
          *detail =
              absl::StrCat(ReplanDetail(*response), " from=", response->replan().progress_source());
        }
        return status;
      });
}

}  // namespace covplan
