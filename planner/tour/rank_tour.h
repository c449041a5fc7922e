// Ordering ranks into a drivable tour: the rank TourModel.
//
// Vertex v = 2k + d stands for rank k driven first->last (d = 0) or
// last->first (d = 1). RankTourCost prices every move with an injected
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
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/robot_model.h"
#include "planner/tour/tour_model.h"
#include "planner/tour/transitions.h"

namespace covplan {

// The TourModel of OARP: one element per rank, two variants (vertex v = 2k + d
// is rank k driven first->last for d = 0, last->first for d = 1).
class RankTourCost final : public TourModel {
 public:
  // InvalidArgument if the start or end pose is outside the reachable free
  // cells. Runs one any-angle search from the start (and end) cell. Moves
  // are priced by `motion` (default: travel time under `robot`).
  static absl::StatusOr<RankTourCost> Create(const Grid& grid, const std::vector<Rank>& ranks,
                                             const TransitionTable& table, const RobotModel& robot,
                                             const StopToken& stop,
                                             std::shared_ptr<const MotionCost> motion = nullptr);

  int num_elements() const override { return num_ranks(); }
  int num_variants(int) const override { return 2; }
  TourElementKind kind(int) const override { return TourElementKind::kRank; }
  bool has_end() const override { return has_end_; }
  double FromStart(int v) const override { return from_start_[v]; }
  // Cost to drive from the exit of u to the entry of v and traverse v.
  double Between(int u, int v) const override;
  // Cost from the exit of u to the end point (the start if no end pose).
  double ToEnd(int u) const override { return to_end_[u]; }

  int num_ranks() const { return static_cast<int>(ranks_->size()); }
  const Pose2& start() const { return start_; }
  double TourTime(const std::vector<int>& vertices) const { return TourCost(vertices); }

  // Waypoints of the whole tour (start, transitions, coverage, return).
  std::vector<Waypoint> BuildPath(const std::vector<int>& vertices) const;

  double Heading(int v) const;
  int EntryEndpoint(int v) const { return (v / 2) * 2 + (v % 2); }
  int ExitEndpoint(int v) const { return (v / 2) * 2 + 1 - (v % 2); }

 private:
  RankTourCost() = default;
  Point2 EndpointPoint(int e) const { return grid_->CellCenter(table_->endpoint(e)); }
  void TransitionPoints(int u, int v, std::vector<Point2>* pts) const;

  const Grid* grid_ = nullptr;
  const std::vector<Rank>* ranks_ = nullptr;
  const TransitionTable* table_ = nullptr;
  std::shared_ptr<const MotionCost> motion_;
  Pose2 start_;
  Pose2 end_;
  bool has_end_ = false;
  std::vector<double> rank_cost_;
  std::vector<double> from_start_, to_end_;
  // Paths start -> entry endpoint and exit endpoint -> end, as points.
  std::vector<std::vector<Point2>> start_paths_, end_paths_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_RANK_TOUR_H_
