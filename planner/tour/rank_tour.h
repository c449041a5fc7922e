// Ordering ranks into a drivable tour: the rank TourModel.
//
// Vertex v = 2k + d stands for rank k driven first->last (d = 0) or
// last->first (d = 1): a two-point element of ElementTourModel, entered at
// transition-table endpoint v and left at v ^ 1 (the endpoints of
// TransitionTable::Build). RankTourCost prices every move with an injected
// MotionCost (default: seconds under the robot model: transition driving +
// turns + the rank's own traversal), from a start pose and back to it (or to
// an end pose). An orderer of planner/tour/tour_model.h picks the order.
//
//   ASSIGN_OR_RETURN(RankTourCost cost, RankTourCost::Create(grid, ranks, *table, robot, stop));
//   ASSIGN_OR_RETURN(TourOrder tour, GtspOrderer(opts).Order(cost, stop));
//   std::vector<Waypoint> path = cost.BuildPath(tour.vertices);
//
// Thread-safety: RankTourCost is immutable after Create.
#ifndef COVPLAN_PLANNER_TOUR_RANK_TOUR_H_
#define COVPLAN_PLANNER_TOUR_RANK_TOUR_H_

#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/element_tour.h"
#include "planner/tour/robot_model.h"
#include "planner/tour/tour_model.h"
#include "planner/tour/transitions.h"

namespace covplan {

// The heading of rank `r` driven first->last (`forward`) or last->first.
double RankHeading(const Rank& r, bool forward);

// Where a rank tour starts: the robot's start pose, else at the first
// rank's first cell, facing along it.
Pose2 RankTourStart(const Grid& grid, const std::vector<Rank>& ranks, const RobotModel& robot);

// The TourModel of OARP: one element per rank, two variants (vertex v = 2k + d
// is rank k driven first->last for d = 0, last->first for d = 1).
class RankTourCost final : public ElementTourModel {
 public:
  // InvalidArgument if the start or end pose is outside the reachable free
  // cells. Runs one any-angle search from the start (and end) cell. Moves
  // are priced by `motion` (default: travel time under `robot`).
  static absl::StatusOr<RankTourCost> Create(const Grid& grid, const std::vector<Rank>& ranks,
                                             const TransitionTable& table, const RobotModel& robot,
                                             const StopToken& stop,
                                             std::shared_ptr<const MotionCost> motion = nullptr);

  int num_elements() const override { return static_cast<int>(ranks_->size()); }
  int num_variants(int) const override { return 2; }
  TourElementKind kind(int) const override { return TourElementKind::kRank; }

  // Waypoints of the whole tour (start, transitions, coverage, return).
  // No sweeps: OARP derives them from its ranks.
  std::vector<Waypoint> BuildPath(const std::vector<int>& vertices) const;

 private:
  RankTourCost() = default;
  // The rank as one straight coverage segment to its exit endpoint.
  void DriveVariant(int v, TourPathWriter* writer) const override;
  absl::Status Unreachable(int element) const override;

  const std::vector<Rank>* ranks_ = nullptr;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_RANK_TOUR_H_
