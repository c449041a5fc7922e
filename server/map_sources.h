// Where a plan's map comes from: a map stored in the MapRepository (loaded
// only when the engine builds an artifact for it) or one sent inline with
// the request. Plans, replans and plans rebuilt after a restart all load
// their maps this way, with the same limits and geometry checks as PutMap.
//
//   MapSource source = MapSourceFor(store, limits, map_id, /*inline_map=*/nullptr);
//   engine.Plan(source, request);
//
// Thread-safety: the source's `load` may run on any thread; the store must
// outlive it.
#ifndef COVPLAN_SERVER_MAP_SOURCES_H_
#define COVPLAN_SERVER_MAP_SOURCES_H_

#include <memory>
#include <string>

#include "api/convert.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/engine/engine.h"
#include "server/map_repository.h"

namespace covplan {

// The map `map_id`: `inline_map` when set, else the stored map of that id
// (NOT_FOUND as MapNotFound when it is gone).
MapSource MapSourceFor(MapRepository* store, const EngineLimits& limits, const std::string& map_id,
                       std::shared_ptr<const v1::Map> inline_map);

}  // namespace covplan

#endif  // COVPLAN_SERVER_MAP_SOURCES_H_
