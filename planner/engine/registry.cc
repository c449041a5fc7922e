// The planners this build ships. Adding a planner: its folder under
// planner/, one Register line here, its options message in the proto.
#include "planner/boustrophedon/boustrophedon_planner.h"
#include "planner/engine/engine.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/stc/stc_planner.h"

namespace covplan {

PlannerRegistry PlannerRegistry::WithBuiltins() {
  PlannerRegistry registry;
  registry.Register(std::make_unique<OarpPlanner>());
  registry.Register(std::make_unique<StcPlanner>());
  registry.Register(std::make_unique<BoustrophedonPlanner>());
  return registry;
}

}  // namespace covplan
