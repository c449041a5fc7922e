// The thesis's LP for the minimum rank partition (eqs. 3.5-3.8, 3.10),
// solved with GLPK's simplex. Kept as the reference solver: the constraint
// matrix is totally unimodular, so the relaxation has an integral optimum;
// integrality is checked and GLPK branch-and-bound takes over if a vertex is
// ever fractional.
//
// Variables per free cell c: x_h(c), x_v(c) in [0,1] with x_h + x_v = 1, and
// y_h(c), y_v(c) >= 0 counting rank starts:
//   y_h(c) >= x_h(c) - x_h(left(c))     (x_h(left) := 0 at a border/blocked cell)
//   y_v(c) >= x_v(c) - x_v(below(c))    (likewise)
// minimise sum y_h + y_v.
//
// Thread-safety: stateless; Partition() is reentrant.
#ifndef COVPLAN_PLANNER_PARTITION_LP_PARTITIONER_H_
#define COVPLAN_PLANNER_PARTITION_LP_PARTITIONER_H_

#include "planner/partition/partitioner.h"

namespace covplan {

class LpPartitioner final : public RankPartitioner {
 public:
  // GLPK cannot be interrupted: the LP gets min(time_limit_s, stop's remaining time).
  explicit LpPartitioner(double time_limit_s = 600.0) : time_limit_s_(time_limit_s) {}
  std::string_view name() const override { return "lp"; }
  absl::StatusOr<RankPartition> Partition(const Grid& grid, const StopToken& stop) const override;

 private:
  double time_limit_s_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_PARTITION_LP_PARTITIONER_H_
