#include "server/map_sources.h"

#include <utility>

#include "planner/common/status_macros.h"
#include "server/not_found.h"
#include "server/request_limits.h"

namespace covplan {

MapSource MapSourceFor(MapRepository* store, const EngineLimits& limits, const std::string& map_id,
                       std::shared_ptr<const v1::Map> inline_map) {
  MapSource source;
  source.map_id = map_id;
  source.load = [store, limits, map_id, inline_map]() -> absl::StatusOr<SiteMap> {
    v1::GetMapResponse stored;
    if (inline_map == nullptr) {
      absl::StatusOr<v1::GetMapResponse> got = store->Get(map_id);
      if (absl::IsNotFound(got.status())) return MapNotFound(map_id);
      if (!got.ok()) return got.status();
      stored = std::move(*got);
    }
    ASSIGN_OR_RETURN(SiteMap site,
                     SiteFromProto(inline_map != nullptr ? *inline_map : stored.map(), limits));
    return site;  // the engine checks its geometry (CheckSiteGeometry)
  };
  return source;
}

}  // namespace covplan
