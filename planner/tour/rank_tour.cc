#include "planner/tour/rank_tour.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "absl/strings/str_format.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

// Points from `pose` to the centre of its cell, then along `cells`.
std::vector<Point2> PosePath(const Grid& grid, const Pose2& pose,
                             const std::vector<CellIndex>& cells) {
  std::vector<Point2> pts = {{pose.x, pose.y}};
  for (const CellIndex& c : cells) pts.push_back(grid.CellCenter(c));
  return pts;
}

}  // namespace

double RankTourCost::Heading(int v) const {
  const Rank& r = (*ranks_)[v / 2];
  const bool forward = v % 2 == 0;
  if (r.orientation == Orientation::kHorizontal) return forward ? 0.0 : M_PI;
  return forward ? M_PI / 2 : -M_PI / 2;
}

absl::StatusOr<RankTourCost> RankTourCost::Create(const Grid& grid, const std::vector<Rank>& ranks,
                                                  const TransitionTable& table,
                                                  const RobotModel& robot, const StopToken& stop,
                                                  std::shared_ptr<const MotionCost> motion) {
  if (ranks.empty()) return absl::InvalidArgumentError("no ranks to order");
  if (table.num_endpoints() != static_cast<int>(ranks.size() * 2)) {
    return absl::InvalidArgumentError("transition table does not match the ranks");
  }
  RankTourCost cost;
  cost.grid_ = &grid;
  cost.ranks_ = &ranks;
  cost.table_ = &table;
  cost.motion_ =
      motion != nullptr ? std::move(motion) : std::make_shared<const TravelTimeCost>(robot);
  cost.IndexVertices();
  if (robot.start) {
    cost.start_ = *robot.start;
  } else {
    // Default: at the first rank's first cell, facing along it.
    const Point2 p = grid.CellCenter(ranks[0].first);
    cost.start_ = {p.x, p.y, ranks[0].orientation == Orientation::kHorizontal ? 0.0 : M_PI / 2};
  }
  cost.has_end_ = robot.end.has_value();
  cost.end_ = robot.end.value_or(cost.start_);
  absl::StatusOr<CellIndex> start_cell = JoinCell(grid, cost.start_, "start");
  if (!start_cell.ok()) return start_cell.status();
  absl::StatusOr<CellIndex> end_cell = JoinCell(grid, cost.end_, "end");
  if (!end_cell.ok()) return end_cell.status();

  const int n = cost.num_vertices();
  cost.rank_cost_.resize(ranks.size());
  for (size_t k = 0; k < ranks.size(); ++k) {
    cost.rank_cost_[k] = cost.motion_->Straight((ranks[k].NumCells() - 1) * grid.cell_size());
  }
  // One search from the start cell and one from the end cell.
  AnyAngleSearch search(grid);
  cost.start_paths_.resize(n);
  cost.from_start_.resize(n);
  if (!search.Run(*start_cell, stop)) {
    return absl::DeadlineExceededError("stopped while routing from the start pose");
  }
  for (int v = 0; v < n; ++v) {
    const CellIndex entry = table.endpoint(cost.EntryEndpoint(v));
    if (!search.Reached(entry)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("rank %d cannot be reached from the start pose (%.3f, %.3f)", v / 2,
                          cost.start_.x, cost.start_.y));
    }
    cost.start_paths_[v] = PosePath(grid, cost.start_, search.PathTo(entry));
    cost.from_start_[v] =
        cost.motion_->Polyline(cost.start_paths_[v], cost.start_.theta, cost.Heading(v)) +
        cost.rank_cost_[v / 2];
  }
  if (cost.has_end_ && !search.Run(*end_cell, stop)) {
    return absl::DeadlineExceededError("stopped while routing to the end pose");
  }
  cost.end_paths_.resize(n);
  cost.to_end_.resize(n);
  for (int u = 0; u < n; ++u) {
    // Any-angle paths are symmetric: reverse end -> exit.
    std::vector<Point2> pts =
        PosePath(grid, cost.end_, search.PathTo(table.endpoint(cost.ExitEndpoint(u))));
    std::reverse(pts.begin(), pts.end());
    cost.end_paths_[u] = std::move(pts);
    cost.to_end_[u] = cost.motion_->Polyline(cost.end_paths_[u], cost.Heading(u), std::nullopt);
  }
  return cost;
}

void RankTourCost::TransitionPoints(int u, int v, std::vector<Point2>* pts) const {
  thread_local std::vector<CellIndex> cells;
  cells.clear();
  table_->AppendPath(ExitEndpoint(u), EntryEndpoint(v), &cells);
  pts->clear();
  for (const CellIndex& c : cells) pts->push_back(grid_->CellCenter(c));
}

double RankTourCost::Between(int u, int v) const {
  if (u / 2 == v / 2) return std::numeric_limits<double>::infinity();
  if (!table_->Reachable(ExitEndpoint(u), EntryEndpoint(v)))
    return std::numeric_limits<double>::infinity();
  thread_local std::vector<Point2> pts;
  TransitionPoints(u, v, &pts);
  return motion_->Polyline(pts, Heading(u), Heading(v)) + rank_cost_[v / 2];
}

std::vector<Waypoint> RankTourCost::BuildPath(const std::vector<int>& vertices) const {
  std::vector<Waypoint> path;
  Point2 at{start_.x, start_.y};
  double heading = start_.theta;
  path.push_back({at.x, at.y, heading, SegmentKind::kStart, -1});
  auto drive = [&](const std::vector<Point2>& pts, SegmentKind kind) {
    for (size_t i = 1; i < pts.size(); ++i) {
      const double dx = pts[i].x - at.x, dy = pts[i].y - at.y;
      if (std::hypot(dx, dy) < kMinSegmentM) continue;
      heading = std::atan2(dy, dx);
      at = pts[i];
      path.push_back({at.x, at.y, heading, kind, -1});
    }
  };
  std::vector<Point2> pts;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const int v = vertices[i];
    if (i == 0) {
      pts = start_paths_[v];
    } else {
      TransitionPoints(vertices[i - 1], v, &pts);
    }
    drive(pts, SegmentKind::kTransition);
    // Coverage of the rank: one straight segment (zero length for a single
    // cell, where the robot still turns onto the rank heading).
    const Point2 exit = EndpointPoint(ExitEndpoint(v));
    heading = Heading(v);
    at = exit;
    path.push_back({exit.x, exit.y, heading, SegmentKind::kCoverage, v / 2});
  }
  if (!vertices.empty()) drive(end_paths_[vertices.back()], SegmentKind::kTransition);
  return path;
}

}  // namespace covplan
