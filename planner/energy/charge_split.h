// The optimal split of an ordered tour of pieces into charge cycles (BC
// Sweep step 4; Beasley's route-first cluster-second): over break points
// 0..n, a cycle covering pieces i..j costs
//   out[i] + work[i] + link[i] + ... + link[j-1] + work[j] + back[j]
// (drive from the station to piece i, the tour from i to j, return), and is
// an arc of a DAG when that cost fits the budget and a charge may happen
// before i and after j. The shortest path from 0 to n (a DP, the DAG being
// topologically ordered) is the cheapest split that keeps the order.
//
//   SplitProblem p; p.out = ...; p.work = ...; p.link = ...; p.back = ...;
//   ASSIGN_OR_RETURN(SplitResult r, SplitTour(p, battery.budget()));
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_ENERGY_CHARGE_SPLIT_H_
#define COVPLAN_PLANNER_ENERGY_CHARGE_SPLIT_H_

#include <utility>
#include <vector>

#include "absl/status/statusor.h"

namespace covplan {

// Per piece k (n pieces; every value >= 0): out[k] station -> start of k
// (including the turn onto it), work[k] the piece, link[k] (n - 1 entries)
// from the end of k to the start of k + 1 along the tour (including the
// turn onto k + 1), back[k] end of k -> station. break_after[k]: a charge
// may follow piece k (empty = everywhere; the last piece always may).
struct SplitProblem {
  std::vector<double> out, work, link, back;
  std::vector<bool> break_after;
  int size() const { return static_cast<int>(work.size()); }
  bool BreakAfter(int k) const { return k + 1 == size() || break_after.empty() || break_after[k]; }
};

struct SplitResult {
  std::vector<std::pair<int, int>> cycles;  // first and last piece of each cycle, in order
  std::vector<double> energy;               // per cycle
  double total = 0.0;
};

// Energy of the cycle covering pieces first..last.
double CycleEnergy(const SplitProblem& p, int first, int last);

// The split of least total energy in which every cycle fits `budget`.
// InvalidArgument for malformed input; FailedPrecondition naming the first
// piece no feasible cycle can reach when there is no split.
absl::StatusOr<SplitResult> SplitTour(const SplitProblem& p, double budget);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENERGY_CHARGE_SPLIT_H_
