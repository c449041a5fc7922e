// libFuzzer target for the PlanRequest edge (api/convert.h): the bytes a client sends as a
// covplan.v1.PlanRequest, turned into the engine's request and site map.
//
// Whatever the bytes hold, a message protobuf accepts must convert to a PlanRequest or come back
// as InvalidArgument, never crash; an accepted request's options must validate to OK or
// InvalidArgument and print their cache text. An inline map goes through SiteFromProto under
// lowered limits, so that one input cannot decode hundreds of megabytes.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "api/convert.h"
#include "google/protobuf/stubs/logging.h"

namespace {

void Check(const absl::Status& s, const char* what) {
  if (!s.ok() && s.code() != absl::StatusCode::kInvalidArgument) {
    std::fprintf(stderr, "%s: unexpected status: %s\n", what, s.ToString().c_str());
    std::abort();
  }
}

covplan::EngineLimits FuzzLimits() {
  covplan::EngineLimits limits;
  limits.max_image_bytes = 1 << 16;
  limits.max_map_pixels = 1 << 18;
  limits.max_area_vertices = 2000;
  return limits;
}

}  // namespace

// protobuf logs every string field it rejects for invalid UTF-8, and the fuzzer makes millions.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  google::protobuf::SetLogHandler(nullptr);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  covplan::v1::PlanRequest proto;
  if (!proto.ParseFromArray(data, static_cast<int>(size))) return 0;

  absl::StatusOr<covplan::PlanRequest> request = covplan::PlanRequestFromProto(proto);
  Check(request.status(), "PlanRequestFromProto");
  if (request.ok()) {
    Check(request->common.Validate(), "CommonOptions::Validate");
    if (request->options != nullptr) {
      Check(request->options->Validate(), "PlannerOptions::Validate");
      (void)request->options->CacheText();
    }
  }
  if (proto.has_map()) {
    static const covplan::EngineLimits limits = FuzzLimits();
    Check(covplan::SiteFromProto(proto.map(), limits).status(), "SiteFromProto");
    (void)covplan::ComputeMapId(proto.map());
  } else {
    Check(covplan::ValidateMapId(proto.map_id()), "ValidateMapId");
  }
  return 0;
}
