#include "server/rpc_methods.h"

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "covplan/v1/covplan.pb.h"

namespace covplan {

const google::protobuf::MethodDescriptor* CoveragePlannerMethod(absl::string_view path) {
  static const std::string* const prefix =
      new std::string(absl::StrCat("/", v1::CoveragePlanner::service_full_name(), "/"));
  if (!absl::StartsWith(path, *prefix)) return nullptr;
  const google::protobuf::ServiceDescriptor* service =
      v1::PutMapRequest::descriptor()->file()->FindServiceByName("CoveragePlanner");
  if (service == nullptr) return nullptr;
  return service->FindMethodByName(std::string(path.substr(prefix->size())));
}

std::string MethodLabel(absl::string_view path) {
  const google::protobuf::MethodDescriptor* method = CoveragePlannerMethod(path);
  return method == nullptr ? "unknown" : method->name();
}

}  // namespace covplan
