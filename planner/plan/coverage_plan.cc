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

size_t CoveragePlan::MemoryBytes() const {
  size_t bytes = sizeof(*this) + path.capacity() * sizeof(Waypoint) + planner.capacity();
  for (const CoverageSweep& s : sweeps) bytes += sizeof(s) + s.cells.capacity() * sizeof(CellIndex);
  bytes += cycles.capacity() * sizeof(ChargeCycle);
  if (detail) bytes += detail->MemoryBytes();
  return bytes;  // the grid is shared with the coverage area, not counted here
}

}  // namespace covplan
