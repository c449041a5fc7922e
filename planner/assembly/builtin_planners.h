// The planners this build ships, assembled above them: the engine and the
// planner interface know no concrete planner, the planners know only the
// interface, and this unit (with PlanCoverage beside it) is where they meet.
// A new planner is a folder under planner/ with a Planner subclass and its
// options struct, one Register line in builtin_planners.cc and, for the API,
// its options message in the proto's oneof (api/convert.cc).
//
//   PlannerRegistry registry = BuiltinPlanners();
//   LocalArtifactCache cache;
//   PlanningEngine engine(&registry, &cache, EngineLimits{});
//
// Thread-safety: BuiltinPlanners is reentrant; the registry it returns is
// read-only once built.
#ifndef COVPLAN_PLANNER_ASSEMBLY_BUILTIN_PLANNERS_H_
#define COVPLAN_PLANNER_ASSEMBLY_BUILTIN_PLANNERS_H_

#include "planner/engine/engine.h"

namespace covplan {

// The planner a request that names none gets.
inline constexpr char kDefaultPlanner[] = "oarp";

// Every shipped planner (oarp, stc, boustrophedon), kDefaultPlanner the
// default.
PlannerRegistry BuiltinPlanners();

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ASSEMBLY_BUILTIN_PLANNERS_H_
