// Ordering ranks into a drivable tour.
//
// Vertex v = 2k + d stands for rank k driven first->last (d = 0) or
// last->first (d = 1). RankTourCost prices every move in seconds with the
// robot model (transition driving + turns + the rank's own traversal), from
// a start pose and back to it (or to an end pose). A RankOrderer picks the
// order: greedy nearest-neighbour, or the anytime GTSP of planner/tour/gtsp.
//
//   ASSIGN_OR_RETURN(RankTourCost cost, RankTourCost::Create(grid, ranks, *table, robot, stop));
//   ASSIGN_OR_RETURN(RankTour tour, MakeOrderer(TourSolver::kGtsp, opts)->Order(cost, stop));
//   std::vector<Waypoint> path = cost.BuildPath(tour);
//
// Thread-safety: RankTourCost is immutable after Create; orderers are
// stateless apart from their options.
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
#include "planner/tour/transitions.h"

namespace covplan {

class RankTourCost {
 public:
  // InvalidArgument if the start or end pose is outside the reachable free
  // cells. Runs one any-angle search from the start (and end) cell.
  static absl::StatusOr<RankTourCost> Create(const Grid& grid, const std::vector<Rank>& ranks,
                                             const TransitionTable& table,
                                             const RobotModel& robot, const StopToken& stop);

  int num_ranks() const { return static_cast<int>(ranks_->size()); }
  int num_vertices() const { return 2 * num_ranks(); }
  bool has_end() const { return has_end_; }
  const Pose2& start() const { return start_; }

  // Seconds to drive from the exit of u to the entry of v and traverse v.
  double Between(int u, int v) const;
  double FromStart(int v) const { return from_start_[v]; }
  // Seconds from the exit of u to the end point (the start if no end pose).
  double ToEnd(int u) const { return to_end_[u]; }
  // Total seconds of a tour given as rank vertices in visiting order.
  double TourTime(const std::vector<int>& vertices) const;

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
  RobotModel robot_;
  Pose2 start_;
  Pose2 end_;
  bool has_end_ = false;
  std::vector<double> rank_time_;
  std::vector<double> from_start_, to_end_;
  // Paths start -> entry endpoint and exit endpoint -> end, as points.
  std::vector<std::vector<Point2>> start_paths_, end_paths_;
};

struct RankTour {
  std::vector<int> vertices;  // rank vertices in visiting order (one per rank)
  double time_s = 0.0;        // RankTourCost::TourTime(vertices)
  bool cut_short = false;     // the search was stopped by the deadline
};

struct OrdererOptions {
  double time_limit_s = 1.0;
  uint64_t seed = 1;
  int num_threads = 1;
  GtspEffort effort = GtspEffort::kDefault;
};

class RankOrderer {
 public:
  virtual ~RankOrderer() = default;
  virtual std::string_view name() const = 0;
  virtual absl::StatusOr<RankTour> Order(const RankTourCost& cost, const StopToken& stop) const = 0;
};

// Nearest unvisited rank vertex from the current position.
class GreedyOrderer final : public RankOrderer {
 public:
  std::string_view name() const override { return "greedy"; }
  absl::StatusOr<RankTour> Order(const RankTourCost& cost, const StopToken& stop) const override;
};

// Anytime GTSP: one set per rank, start vertex, optional end vertex with a
// zero-cost arc end -> start. Warm-started from the greedy tour.
class GtspOrderer final : public RankOrderer {
 public:
  explicit GtspOrderer(OrdererOptions options) : options_(options) {}
  std::string_view name() const override { return "gtsp"; }
  absl::StatusOr<RankTour> Order(const RankTourCost& cost, const StopToken& stop) const override;

 private:
  OrdererOptions options_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_RANK_TOUR_H_
