// One call from a fleet request to a fleet plan, on the planning engine, for
// every planner: a single-robot tour of the whole site gives the units and
// their order (units.h); the division (division.h) gives each robot its
// cells; each robot's share is planned by the requested planner with the
// robot's own model, start, end and battery (PlanningEngine::PlanPart), so
// every robot plan is an ordinary CoveragePlan. With the makespan division
// the split is then rebalanced on the real plans: each robot's piece costs
// are scaled by its real duration over the split's estimate and the tour is
// split again, while the budget lasts and the makespan drops. A fleet of one
// is exactly the single-robot plan.
//
// Budget: the request's time_limit_s (and its stop token) covers the whole
// fleet plan: about 30 % for the reference tour's search, the rest for the robots'
// plans and the rebalancing rounds. Robots are planned concurrently on up to
// common.num_threads threads.
//
// Thread-safety: reentrant; thread-safe when the engine is.
#ifndef COVPLAN_PLANNER_FLEET_FLEET_PLANNER_H_
#define COVPLAN_PLANNER_FLEET_FLEET_PLANNER_H_

#include "absl/status/statusor.h"
#include "planner/engine/engine.h"
#include "planner/fleet/fleet_request.h"

namespace covplan {

absl::StatusOr<FleetPlan> PlanFleet(const PlanningEngine& engine, const MapSource& source,
                                    const FleetRequest& request);

// Fills the fleet's figures (makespan, durations, shares, covered cells, the
// safety report) from the robots' plans; `cover_cells` is the site's.
void FillFleetFigures(const FleetRequest& request, int64_t cover_cells, FleetPlan* plan);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_FLEET_PLANNER_H_
