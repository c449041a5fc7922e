// SHA-256 digests for content-derived ids and on-disk checksums.
//
//   std::string hex = Sha256Hex("abc");  // 64 lowercase hex digits
//
// Thread-safety: stateless, safe to call concurrently.
#ifndef COVPLAN_API_DIGEST_H_
#define COVPLAN_API_DIGEST_H_

#include <string>
#include "absl/strings/string_view.h"

namespace covplan {

std::string Sha256Hex(absl::string_view bytes);

}  // namespace covplan

#endif  // COVPLAN_API_DIGEST_H_
