#include "server/request_limits.h"

#include <vector>

#include "absl/strings/str_cat.h"
#include "google/protobuf/descriptor.h"

namespace covplan {
namespace {

using ::google::protobuf::FieldDescriptor;
using ::google::protobuf::Message;
using ::google::protobuf::Reflection;

absl::Status TooLong(const std::string& path, size_t size, size_t limit) {
  return absl::InvalidArgumentError(
      absl::StrCat(path, " is ", size, " bytes; the limit is ", limit, " bytes"));
}

bool MayHoldStrings(const google::protobuf::Descriptor* type, int depth = 0) {
  if (depth > 16) return true;  // deep or recursive: walk it
  for (int i = 0; i < type->field_count(); ++i) {
    const FieldDescriptor* field = type->field(i);
    if (field->type() == FieldDescriptor::TYPE_STRING) return true;
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE &&
        MayHoldStrings(field->message_type(), depth + 1)) {
      return true;
    }
  }
  return false;
}

absl::Status CheckMessage(const Message& message, const std::string& prefix) {
  const Reflection* reflection = message.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);  // set fields only
  for (const FieldDescriptor* field : fields) {
    const std::string path =
        prefix.empty() ? field->name() : absl::StrCat(prefix, ".", field->name());
    if (field->type() == FieldDescriptor::TYPE_STRING) {
      const size_t limit = StringLimitFor(field->full_name());
      if (field->is_repeated()) {
        const int n = reflection->FieldSize(message, field);
        for (int i = 0; i < n; ++i) {
          std::string scratch;
          const std::string& value =
              reflection->GetRepeatedStringReference(message, field, i, &scratch);
          if (value.size() > limit)
            return TooLong(absl::StrCat(path, "[", i, "]"), value.size(), limit);
        }
      } else {
        std::string scratch;
        const std::string& value = reflection->GetStringReference(message, field, &scratch);
        if (value.size() > limit) return TooLong(path, value.size(), limit);
      }
    } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      // Only message types that can hold strings are walked (waypoints and
      // points cannot), so large inline plans stay cheap to check.
      if (!MayHoldStrings(field->message_type())) continue;
      if (field->is_repeated()) {
        const int n = reflection->FieldSize(message, field);
        for (int i = 0; i < n; ++i) {
          if (absl::Status s = CheckMessage(reflection->GetRepeatedMessage(message, field, i),
                                            absl::StrCat(path, "[", i, "]"));
              !s.ok()) {
            return s;
          }
        }
      } else if (absl::Status s = CheckMessage(reflection->GetMessage(message, field), path);
                 !s.ok()) {
        return s;
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

size_t StringLimitFor(const std::string& full_field_name) {
  if (full_field_name == "covplan.v1.PutMapRequest.name" ||
      full_field_name == "covplan.v1.MapInfo.name") {
    return kMapNameLimit;
  }
  if (full_field_name == "covplan.v1.RasterMap.yaml") return kYamlLimit;
  // One row of a plan's grid per string (inline plans sent back to Replan).
  if (full_field_name == "covplan.v1.Grid.free_cells") return 1 << 16;
  if (full_field_name == "covplan.v1.Termination.detail") return 4096;
  return kDefaultStringLimit;
}

absl::Status CheckRequestStrings(const google::protobuf::Message& request) {
  return CheckMessage(request, "");
}

std::string QuotePrefix(absl::string_view text, size_t max_chars) {
  if (text.size() <= max_chars) return std::string(text);
  return absl::StrCat(text.substr(0, max_chars), "...(", text.size(), " bytes)");
}

}  // namespace covplan
