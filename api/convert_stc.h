// The STC planner's messages at the proto edge: StcOptions in, StcDetail out
// and back (GetPlan, inline plans). Errors name the proto field
// ("stc.tree: unknown value 7").
//
//   ASSIGN_OR_RETURN(auto options, StcOptionsFromProto(request.stc()));
//   StcDetailToProto(*plan.detail_as<StcDetail>(), response.mutable_stc());
//
// Thread-safety: pure functions.
#ifndef COVPLAN_API_CONVERT_STC_H_
#define COVPLAN_API_CONVERT_STC_H_

#include <memory>

#include "absl/status/statusor.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/stc/stc_planner.h"

namespace covplan {

absl::StatusOr<std::shared_ptr<const StcOptions>> StcOptionsFromProto(
    const v1::StcOptions& options);
void StcDetailToProto(const StcDetail& detail, v1::StcDetail* out);
absl::StatusOr<std::shared_ptr<const StcDetail>> StcDetailFromProto(const v1::StcDetail& detail);

}  // namespace covplan

#endif  // COVPLAN_API_CONVERT_STC_H_
