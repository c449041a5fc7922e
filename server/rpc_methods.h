// The CoveragePlanner methods by their gRPC path, for the parts of the
// server that see a call before its handler does (interceptors, the
// transport's token check) and must name it with a bounded label.
//
//   const google::protobuf::MethodDescriptor* m =
//       CoveragePlannerMethod("/covplan.v1.CoveragePlanner/Plan");  // Plan
//   MethodLabel("/x.Y/Z");  // "unknown"
//
// Thread-safety: stateless (the descriptors are the generated pool's).
#ifndef COVPLAN_SERVER_RPC_METHODS_H_
#define COVPLAN_SERVER_RPC_METHODS_H_

#include <string>

#include "absl/strings/string_view.h"
#include "google/protobuf/descriptor.h"

namespace covplan {

// The CoveragePlanner method that `path` ("/covplan.v1.CoveragePlanner/Plan")
// calls, or nullptr for any other path.
const google::protobuf::MethodDescriptor* CoveragePlannerMethod(absl::string_view path);

// The method's name for metrics and logs ("Plan"), or "unknown" for a path
// that is no CoveragePlanner method, so labels stay bounded whatever a
// client sends.
std::string MethodLabel(absl::string_view path);

}  // namespace covplan

#endif  // COVPLAN_SERVER_RPC_METHODS_H_
