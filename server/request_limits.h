// Bounds on what a request may carry, checked before any work is queued.
// (The geometry a map must have to be plannable is the engine's:
// CheckSiteGeometry in planner/engine/site.h.)
//
//   if (absl::Status s = CheckRequestStrings(*request); !s.ok()) Reject(s);
//   // "name is 10485760 bytes; the limit is 256 bytes"
//
// Every string field of every message (nested and repeated ones included) is
// bounded: a few known fields have their own limit (kStringLimits), all others
// kDefaultStringLimit. Bytes fields (images) are bounded elsewhere
// (EngineLimits, planner/engine/limits.h). QuotePrefix is how errors quote user input: at most a
// short prefix, so a reply never repeats megabytes back.
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_SERVER_REQUEST_LIMITS_H_
#define COVPLAN_SERVER_REQUEST_LIMITS_H_

#include <cstddef>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "google/protobuf/message.h"

namespace covplan {

inline constexpr size_t kDefaultStringLimit = 1024;
inline constexpr size_t kMapNameLimit = 256;
inline constexpr size_t kYamlLimit = 64 << 10;
// Status messages and log values are cut to this many bytes.
inline constexpr size_t kMaxMessageBytes = 1024;

// The limit of a string field by its full protobuf name
// ("covplan.v1.PutMapRequest.name").
size_t StringLimitFor(const std::string& full_field_name);

// InvalidArgument naming the first over-long string field by its path in
// the request (e.g. "plan.request.map.raster.yaml") and its limit.
absl::Status CheckRequestStrings(const google::protobuf::Message& request);

// `text` if short, else its first `max_chars` bytes and "...(N bytes)".
std::string QuotePrefix(absl::string_view text, size_t max_chars = 64);

}  // namespace covplan

#endif  // COVPLAN_SERVER_REQUEST_LIMITS_H_
