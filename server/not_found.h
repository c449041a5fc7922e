// The NOT_FOUND answers for a map or plan id that does not exist. They are
// also given for another tenant's id, so a caller cannot tell the two apart;
// the id is quoted by a bounded prefix.
//
//   if (!OwnsMap(call.tenant_tag, map_id)) return MapNotFound(map_id);
//
// Thread-safety: stateless functions.
#ifndef COVPLAN_SERVER_NOT_FOUND_H_
#define COVPLAN_SERVER_NOT_FOUND_H_

#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace covplan {

inline absl::Status MapNotFound(const std::string& map_id) {
  return absl::NotFoundError(
      absl::StrCat("unknown map_id ", map_id.substr(0, 80), "; PutMap it first"));
}

inline absl::Status PlanNotFound(const std::string& plan_id) {
  return absl::NotFoundError(
      absl::StrCat("unknown or expired plan_id '", plan_id.substr(0, 80), "'"));
}

}  // namespace covplan

#endif  // COVPLAN_SERVER_NOT_FOUND_H_
