// How `covplan` commands reach a server: the target plus TLS files and a
// bearer token, parsed the same way by every command that talks to one.
//
//   ASSIGN_OR_RETURN(ParsedArgs a, ParseArgs(args, WithConnectionFlags({"server", "map"}), {}));
//   ASSIGN_OR_RETURN(Connection server, ConnectionFromArgs(a,
//   a.Get("server").value_or(kDefaultServer))); std::unique_ptr<RemotePlanner> remote =
//   RemotePlanner::Connect(server);
//
// --tls-ca / --tls-cert / --tls-key are PEM files (the CA to trust; a client
// certificate and its key for mutual TLS); any of them turns TLS on (without
// --tls-ca the system's roots are trusted). --token TOKEN or --token-file
// FILE sends "authorization: Bearer TOKEN" with every call; prefer the file,
// a token on the command line is visible to other local users.
//
// Thread-safety: plain value types and free functions.
#ifndef COVPLAN_CLIENT_CONNECTION_H_
#define COVPLAN_CLIENT_CONNECTION_H_

#include <set>
#include <string>

#include "absl/status/statusor.h"
#include "client/args.h"

namespace covplan {

inline constexpr char kDefaultServer[] = "127.0.0.1:50051";

struct Connection {
  std::string target;
  bool tls = false;
  std::string ca_pem;    // empty with TLS: the system's roots
  std::string cert_pem;  // client certificate (mutual TLS), with key_pem
  std::string key_pem;
  std::string token;  // empty: no authorization metadata
};

// The value flags above added to a command's own.
std::set<std::string> WithConnectionFlags(std::set<std::string> flags);
// Reads the files the flags name. InvalidArgument for an unreadable or
// non-PEM file, --tls-cert without --tls-key (or the reverse), --token with
// --token-file, or an empty token.
absl::StatusOr<Connection> ConnectionFromArgs(const ParsedArgs& args, const std::string& target);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_CONNECTION_H_
