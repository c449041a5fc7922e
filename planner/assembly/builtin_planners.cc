#include "planner/assembly/builtin_planners.h"

#include <memory>

#include "planner/boustrophedon/boustrophedon_planner.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/stc/stc_planner.h"

namespace covplan {

PlannerRegistry BuiltinPlanners() {
  PlannerRegistry registry;
  registry.Register(std::make_unique<OarpPlanner>());
  registry.Register(std::make_unique<StcPlanner>());
  registry.Register(std::make_unique<BoustrophedonPlanner>());
  registry.SetDefault(kDefaultPlanner);
  return registry;
}

}  // namespace covplan
