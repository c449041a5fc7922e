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

// The free cell where the robot joins the grid: the pose's own cell, or, when
// that cell is blocked (a dock against a wall stands in a cell that is mostly
// wall), the adjacent free cell whose centre is nearest. The path then starts
// with the short move from the pose onto that cell.
absl::StatusOr<CellIndex> PoseCell(const Grid& grid, const Pose2& p, const char* what) {
  const CellIndex c = grid.CellAt({p.x, p.y});
  if (grid.IsFree(c)) return c;
  std::optional<CellIndex> best;
  double best_d2 = std::numeric_limits<double>::infinity();
  // Far outside the grid (CellAt clamps to -2 / n + 1): no free neighbour.
  const bool near_grid = c.row >= -1 && c.col >= -1 && c.row <= grid.rows() && c.col <= grid.cols();
  for (int dr = -1; near_grid && dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      const CellIndex n{c.row + dr, c.col + dc};
      if (!grid.IsFree(n)) continue;
      const Point2 q = grid.CellCenter(n);
      const double d2 = (q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y);
      if (d2 < best_d2) best_d2 = d2, best = n;
    }
  }
  if (best) return *best;
  return absl::InvalidArgumentError(absl::StrFormat(
      "%s pose (%.3f, %.3f) is neither in nor next to a reachable free grid cell (cells of "
      "%.3f m; only the largest connected free area is planned)",
      what, p.x, p.y, grid.cell_size()));
}

// Points from `pose` to the centre of its cell, then along `cells`.
std::vector<Point2> PosePath(const Grid& grid, const Pose2& pose, const std::vector<CellIndex>& cells) {
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
                                                  const RobotModel& robot, const StopToken& stop) {
  if (ranks.empty()) return absl::InvalidArgumentError("no ranks to order");
  if (table.num_endpoints() != static_cast<int>(ranks.size() * 2)) {
    return absl::InvalidArgumentError("transition table does not match the ranks");
  }
  RankTourCost cost;
  cost.grid_ = &grid;
  cost.ranks_ = &ranks;
  cost.table_ = &table;
  cost.robot_ = robot;
  if (robot.start) {
    cost.start_ = *robot.start;
  } else {
    // Default: at the first rank's first cell, facing along it.
    const Point2 p = grid.CellCenter(ranks[0].first);
    cost.start_ = {p.x, p.y, ranks[0].orientation == Orientation::kHorizontal ? 0.0 : M_PI / 2};
  }
  cost.has_end_ = robot.end.has_value();
  cost.end_ = robot.end.value_or(cost.start_);
  absl::StatusOr<CellIndex> start_cell = PoseCell(grid, cost.start_, "start");
  if (!start_cell.ok()) return start_cell.status();
  absl::StatusOr<CellIndex> end_cell = PoseCell(grid, cost.end_, "end");
  if (!end_cell.ok()) return end_cell.status();

  const int n = cost.num_vertices();
  cost.rank_time_.resize(ranks.size());
  for (size_t k = 0; k < ranks.size(); ++k) {
    cost.rank_time_[k] = robot.StraightTime((ranks[k].NumCells() - 1) * grid.cell_size());
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
      return absl::InvalidArgumentError(absl::StrFormat(
          "rank %d cannot be reached from the start pose (%.3f, %.3f)", v / 2, cost.start_.x,
          cost.start_.y));
    }
    cost.start_paths_[v] = PosePath(grid, cost.start_, search.PathTo(entry));
    cost.from_start_[v] = TimePolyline(robot, cost.start_paths_[v], cost.start_.theta,
                                       cost.Heading(v)).time_s +
                          cost.rank_time_[v / 2];
  }
  if (cost.has_end_ && !search.Run(*end_cell, stop)) {
    return absl::DeadlineExceededError("stopped while routing to the end pose");
  }
  cost.end_paths_.resize(n);
  cost.to_end_.resize(n);
  for (int u = 0; u < n; ++u) {
    // Any-angle paths are symmetric: reverse end -> exit.
    std::vector<Point2> pts = PosePath(grid, cost.end_, search.PathTo(table.endpoint(cost.ExitEndpoint(u))));
    std::reverse(pts.begin(), pts.end());
    cost.end_paths_[u] = std::move(pts);
    cost.to_end_[u] = TimePolyline(robot, cost.end_paths_[u], cost.Heading(u), std::nullopt).time_s;
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
  if (!table_->Reachable(ExitEndpoint(u), EntryEndpoint(v))) return std::numeric_limits<double>::infinity();
  thread_local std::vector<Point2> pts;
  TransitionPoints(u, v, &pts);
  return TimePolyline(robot_, pts, Heading(u), Heading(v)).time_s + rank_time_[v / 2];
}

double RankTourCost::TourTime(const std::vector<int>& vertices) const {
  if (vertices.empty()) return 0.0;
  double t = FromStart(vertices[0]);
  for (size_t i = 1; i < vertices.size(); ++i) t += Between(vertices[i - 1], vertices[i]);
  return t + ToEnd(vertices.back());
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

absl::StatusOr<RankTour> GreedyOrderer::Order(const RankTourCost& cost, const StopToken& stop) const {
  const int n = cost.num_vertices();
  std::vector<bool> used(cost.num_ranks(), false);
  RankTour tour;
  int current = -1;
  for (int step = 0; step < cost.num_ranks(); ++step) {
    if ((step & 63) == 63 && stop.cancelled()) return absl::CancelledError("greedy ordering cancelled");
    int best = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    for (int v = 0; v < n; ++v) {
      if (used[v / 2]) continue;
      const double c = current < 0 ? cost.FromStart(v) : cost.Between(current, v);
      if (c < best_cost) best_cost = c, best = v;
    }
    if (best < 0) return absl::InternalError("greedy ordering found no reachable rank");
    used[best / 2] = true;
    tour.vertices.push_back(best);
    current = best;
  }
  tour.time_s = cost.TourTime(tour.vertices);
  return tour;
}

absl::StatusOr<RankTour> GtspOrderer::Order(const RankTourCost& cost, const StopToken& stop) const {
  // Warm start and fallback: the greedy tour.
  absl::StatusOr<RankTour> greedy = GreedyOrderer().Order(cost, stop);
  if (!greedy.ok()) return greedy.status();
  const int n = cost.num_vertices();
  if (cost.num_ranks() <= 1) return greedy;

  const int start = n, end = cost.has_end() ? n + 1 : -1;
  GtspInstance inst;
  inst.num_vertices = n + 1 + (cost.has_end() ? 1 : 0);
  const double inf = GtspInstance::kInfeasibleCost;
  inst.costs.assign(static_cast<size_t>(inst.num_vertices) * inst.num_vertices, inf);
  auto at = [&](int i, int j) -> double& { return inst.costs[static_cast<size_t>(i) * inst.num_vertices + j]; };
  for (int u = 0; u < n; ++u) {
    if ((u & 15) == 15 && stop.ShouldStop()) {
      greedy->cut_short = true;
      return greedy;
    }
    for (int v = 0; v < n; ++v) {
      const double c = cost.Between(u, v);
      if (std::isfinite(c)) at(u, v) = c;
    }
    at(start, u) = cost.FromStart(u);
    if (end >= 0) {
      at(u, end) = cost.ToEnd(u);
    } else {
      at(u, start) = cost.ToEnd(u);
    }
  }
  if (end >= 0) at(end, start) = 0.0;
  for (int k = 0; k < cost.num_ranks(); ++k) inst.sets.push_back({2 * k, 2 * k + 1});
  inst.sets.push_back({start});
  if (end >= 0) inst.sets.push_back({end});

  GtspOptions opt;
  opt.seed = options_.seed;
  opt.num_threads = options_.num_threads;
  opt.effort = options_.effort;
  opt.stop = stop.WithEarlierDeadline(absl::Now() + absl::Seconds(options_.time_limit_s));
  opt.initial_tour.push_back(start);
  for (int v : greedy->vertices) opt.initial_tour.push_back(v);
  if (end >= 0) opt.initial_tour.push_back(end);
  absl::StatusOr<GtspResult> result = SolveGtsp(inst, opt);
  if (!result.ok()) return result.status();

  // Rotate the cycle to begin at the start vertex; drop start/end.
  std::vector<int> cycle = result->tour;
  auto it = std::find(cycle.begin(), cycle.end(), start);
  if (it == cycle.end()) return absl::InternalError("GTSP tour misses the start vertex");
  std::rotate(cycle.begin(), it, cycle.end());
  RankTour tour;
  for (int v : cycle) {
    if (v < n) tour.vertices.push_back(v);
  }
  tour.time_s = cost.TourTime(tour.vertices);
  tour.cut_short = result->stopped_early && stop.ShouldStop();
  if (greedy->time_s < tour.time_s) {
    greedy->cut_short = tour.cut_short;
    return greedy;
  }
  return tour;
}

}  // namespace covplan
