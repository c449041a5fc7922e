// `covplan health`: asks a server's grpc.health.v1.Health/Check and exits 0
// only when it reports SERVING (the container HEALTHCHECK and scripts use it;
// grpc_health_probe is not packaged in Debian 12).
//
//   covplan health --server 127.0.0.1:50051 [--service NAME] [--timeout-ms 2000]
//
// Thread-safety: not applicable (command entry point).
#ifndef COVPLAN_CLIENT_HEALTH_COMMAND_H_
#define COVPLAN_CLIENT_HEALTH_COMMAND_H_

#include <string>
#include <vector>

namespace covplan {

int RunHealthCommand(const std::vector<std::string>& args);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_HEALTH_COMMAND_H_
