// The map-file flags every command that reads a map accepts:
// --resolution M, --free-thresh P, --occupied-thresh P and --negate, as the
// overrides MapProtoFromFile applies to a YAML or bare image.
//
//   ASSIGN_OR_RETURN(MapFileOverrides overrides, MapFileOverridesFromFlags(a));
//   ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(path, overrides, limits));
#ifndef COVPLAN_CLIENT_MAP_FLAGS_H_
#define COVPLAN_CLIENT_MAP_FLAGS_H_

#include "absl/status/statusor.h"
#include "api/convert.h"
#include "client/args.h"

namespace covplan {

// InvalidArgument when a numeric flag is present but not a number.
absl::StatusOr<MapFileOverrides> MapFileOverridesFromFlags(const ParsedArgs& a);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_MAP_FLAGS_H_
