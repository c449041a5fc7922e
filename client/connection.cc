#include "client/connection.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace covplan {
namespace {

absl::StatusOr<std::string> ReadPem(const ParsedArgs& args, const std::string& flag) {
  const std::string path = *args.Get(flag);
  absl::StatusOr<std::string> text = ReadFlagFile(flag, path);
  if (!text.ok()) return text.status();
  if (!absl::StrContains(*text, "-----BEGIN ")) {
    return absl::InvalidArgumentError(absl::StrCat("--", flag, " ", path, ": not a PEM file"));
  }
  return text;
}

}  // namespace

std::set<std::string> WithConnectionFlags(std::set<std::string> flags) {
  flags.insert({"tls-ca", "tls-cert", "tls-key", "token", "token-file"});
  return flags;
}

absl::StatusOr<Connection> ConnectionFromArgs(const ParsedArgs& args, const std::string& target) {
  Connection c;
  c.target = target;
  if (args.Get("tls-cert").has_value() != args.Get("tls-key").has_value()) {
    return absl::InvalidArgumentError("--tls-cert and --tls-key go together");
  }
  if (args.Get("tls-ca")) {
    absl::StatusOr<std::string> ca = ReadPem(args, "tls-ca");
    if (!ca.ok()) return ca.status();
    c.ca_pem = std::move(*ca);
    c.tls = true;
  }
  if (args.Get("tls-cert")) {
    absl::StatusOr<std::string> cert = ReadPem(args, "tls-cert");
    if (!cert.ok()) return cert.status();
    absl::StatusOr<std::string> key = ReadPem(args, "tls-key");
    if (!key.ok()) return key.status();
    c.cert_pem = std::move(*cert);
    c.key_pem = std::move(*key);
    c.tls = true;
  }
  if (args.Get("token") && args.Get("token-file")) {
    return absl::InvalidArgumentError("--token and --token-file exclude each other");
  }
  if (args.Get("token")) {
    c.token = *args.Get("token");
    if (c.token.empty()) return absl::InvalidArgumentError("--token: must not be empty");
  } else if (args.Get("token-file")) {
    absl::StatusOr<std::string> text = ReadFlagFile("token-file", *args.Get("token-file"));
    if (!text.ok()) return text.status();
    c.token = std::string(absl::StripAsciiWhitespace(*text));
    if (c.token.empty()) return absl::InvalidArgumentError("--token-file: the file holds no token");
  }
  for (char ch : c.token) {
    if (ch <= ' ' || ch > '~') {
      return absl::InvalidArgumentError("the token must be printable ASCII without spaces");
    }
  }
  return c;
}

}  // namespace covplan
