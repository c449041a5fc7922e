#include "planner/plan/coverage_plan.h"

namespace covplan {

const char* TerminationReasonName(TerminationReason r) {
  switch (r) {
    case TerminationReason::kConverged:
      return "converged";
    case TerminationReason::kFeasibleLimitReached:
      return "feasible_limit_reached";
  }
  return "unknown";
}

const char* TerminationLimitName(TerminationLimit l) {
  switch (l) {
    case TerminationLimit::kNone:
      return "none";
    case TerminationLimit::kTime:
      return "time";
    case TerminationLimit::kDeadline:
      return "deadline";
    case TerminationLimit::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

const char* PlanOriginName(PlanOrigin s) {
  switch (s) {
    case PlanOrigin::kCold:
      return "cold";
    case PlanOrigin::kCacheHit:
      return "cache_hit";
    case PlanOrigin::kImproved:
      return "improved";
    case PlanOrigin::kWarmStart:
      return "warm_start";
  }
  return "unknown";
}

size_t CoveragePlan::MemoryBytes() const {
  size_t bytes = sizeof(*this) + path.capacity() * sizeof(Waypoint) + planner.capacity();
  bytes += sweeps.capacity() * sizeof(CoverageSweep);
  for (const CoverageSweep& s : sweeps) bytes += s.cells.capacity() * sizeof(CellIndex);
  bytes += cycles.capacity() * sizeof(ChargeCycle) + tour_vertices.capacity() * sizeof(int);
  bytes += stats.partition_solver.capacity() + stats.tour_solver.capacity();
  bytes += termination.detail.capacity();
  if (detail) bytes += detail->MemoryBytes();
  return bytes;  // the grid is shared with the coverage area, not counted here
}

}  // namespace covplan
