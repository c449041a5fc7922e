// How a planner orders its sweeps: the vocabulary every planner that tours
// sweeps with the GTSP shares (OARP's ranks, boustrophedon's cells), kept
// below the planners so that neither includes the other.
//
//   OarpOptions o; o.tour_solver = TourSolver::kGreedy;
//   RETURN_IF_ERROR(CheckTourSolver(o.tour_solver, "oarp.tour_solver"));
//
// Thread-safety: an enum and a pure function.
#ifndef COVPLAN_PLANNER_TOUR_TOUR_SOLVER_H_
#define COVPLAN_PLANNER_TOUR_TOUR_SOLVER_H_

#include <string>

#include "absl/status/status.h"

namespace covplan {

// kGreedy: nearest next sweep; kGtsp: the anytime GTSP search.
enum class TourSolver { kGreedy, kGtsp };

// InvalidArgument "<field>: unknown solver" unless `solver` is one of the above
// (an enum read from a number may hold anything).
inline absl::Status CheckTourSolver(TourSolver solver, const std::string& field) {
  if (solver == TourSolver::kGreedy || solver == TourSolver::kGtsp) return absl::OkStatus();
  return absl::InvalidArgumentError(field + ": unknown solver");
}

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_TOUR_SOLVER_H_
