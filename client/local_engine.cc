#include "client/local_engine.h"

#include <utility>

#include "api/convert.h"

namespace covplan {

LocalEngine::LocalEngine(const EngineLimits& limits, PlannerRegistry registry)
    : registry_(std::move(registry)), engine_(&registry_, &cache_, limits) {}

MapSource MapSourceFor(const v1::Map& map, const EngineLimits& limits) {
  MapSource source;
  source.map_id = ComputeMapId(map);
  source.load = [&map, limits]() { return SiteFromProto(map, limits); };
  return source;
}

}  // namespace covplan
