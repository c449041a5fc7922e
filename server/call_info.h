// What a handler knows about its call, for logs, metrics and the limits
// that depend on when the call arrived and when it must be answered. Filled
// by CallGate::Start (server/call_gate.h) from the gRPC context; the parts
// below the gate (admission, the plan and replan work) read it without
// depending on gRPC.
//
// Thread-safety: a plain value, copied into the work a call queues.
#ifndef COVPLAN_SERVER_CALL_INFO_H_
#define COVPLAN_SERVER_CALL_INFO_H_

#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"

namespace covplan {

struct CallInfo {
  const char* method = "";
  std::string request_id;
  absl::Time start;
  absl::Time deadline = absl::InfiniteFuture();
  // With --token_file: the caller's tenant tag (server/tenant_tokens.h), or
  // `auth` says why the call is refused. Empty tag and OK without one.
  std::string tenant_tag;
  // With --token_file: the caller's tenant, "unauthenticated" when `auth`
  // refuses the call; a field of the call's log line and a label of its
  // request metrics. Empty without a token file.
  std::string tenant;
  absl::Status auth;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_CALL_INFO_H_
