#include "server/malformed_request_interceptor.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "google/protobuf/descriptor.h"
#include "server/log.h"
#include "server/rpc_methods.h"

namespace covplan {
namespace {

using grpc::experimental::InterceptionHookPoints;

class MalformedRequestInterceptor final : public grpc::experimental::Interceptor {
 public:
  MalformedRequestInterceptor(const google::protobuf::MethodDescriptor* method,
                              ServerMetrics* metrics)
      : method_(method), metrics_(metrics), start_(absl::Now()) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      const grpc::Status status = methods->GetSendStatus();
      // Our handlers never answer UNIMPLEMENTED: this is gRPC's reply to a
      // request it could not deserialise.
      if (status.error_code() == grpc::StatusCode::UNIMPLEMENTED &&
          status.error_message().empty()) {
        const std::string message = absl::StrCat(
            "request is not a valid ", method_->input_type()->full_name(), " protobuf message");
        methods->ModifySendStatus(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, message));
        const double seconds = absl::ToDoubleSeconds(absl::Now() - start_);
        metrics_->RecordRequest(method_->name(), "INVALID_ARGUMENT", seconds);
        LogLine("warn", "request finished",
                {{"req", "-"},
                 {"method", method_->name()},
                 {"code", "INVALID_ARGUMENT"},
                 {"ms", absl::StrFormat("%.1f", seconds * 1e3)},
                 {"late", "false"},
                 {"detail", message}});
      }
    }
    methods->Proceed();
  }

 private:
  const google::protobuf::MethodDescriptor* const method_;
  ServerMetrics* const metrics_;
  const absl::Time start_;
};

class Factory final : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit Factory(ServerMetrics* metrics) : metrics_(metrics) {}

  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override {
    // "/covplan.v1.CoveragePlanner/PutMap": only our unary methods.
    const char* name = info->method();
    if (name == nullptr || info->type() != grpc::experimental::ServerRpcInfo::Type::UNARY) {
      return nullptr;
    }
    const google::protobuf::MethodDescriptor* method = CoveragePlannerMethod(name);
    if (method == nullptr) return nullptr;
    return new MalformedRequestInterceptor(method, metrics_);
  }

 private:
  ServerMetrics* const metrics_;
};

}  // namespace

std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>>
MalformedRequestInterceptors(ServerMetrics* metrics) {
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> factories;
  factories.push_back(std::make_unique<Factory>(metrics));
  return factories;
}

}  // namespace covplan
