// The engine a client command plans on in this process (`covplan plan
// --local`, compare, partition, load): the shipped planners, an artifact
// cache of its own and the given limits, over maps given as protos. One
// set-up for every command, so they cannot drift apart.
//
//   LocalEngine local(limits);
//   MapSource source = MapSourceFor(map, limits);
//   ASSIGN_OR_RETURN(EngineResult result, local.engine().Plan(source, request));
//
// Thread-safety: engine() is thread-safe (its cache is); a MapSource borrows
// its map, which must outlive it.
#ifndef COVPLAN_CLIENT_LOCAL_ENGINE_H_
#define COVPLAN_CLIENT_LOCAL_ENGINE_H_

#include "covplan/v1/covplan.pb.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/artifact_cache.h"
#include "planner/engine/engine.h"

namespace covplan {

class LocalEngine {
 public:
  explicit LocalEngine(const EngineLimits& limits = {},
                       PlannerRegistry registry = BuiltinPlanners());
  LocalEngine(const LocalEngine&) = delete;
  LocalEngine& operator=(const LocalEngine&) = delete;

  const PlanningEngine& engine() const { return engine_; }

 private:
  PlannerRegistry registry_;
  LocalArtifactCache cache_;
  PlanningEngine engine_;
};

// `map` keyed by its content id (ComputeMapId), decoded within `limits`
// (SiteFromProto) when an artifact needs it. `map` must outlive the source.
MapSource MapSourceFor(const v1::Map& map, const EngineLimits& limits);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_LOCAL_ENGINE_H_
