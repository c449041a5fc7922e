#include "planner/tour/element_tour.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"
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

TourPathWriter::TourPathWriter(const Pose2& start, std::vector<Waypoint>* path,
                               std::vector<CoverageSweep>* sweeps)
    : at_{start.x, start.y}, heading_(start.theta), path_(path), sweeps_(sweeps) {
  path_->push_back({at_.x, at_.y, heading_, SegmentKind::kStart, -1});
}

void TourPathWriter::Transit(const std::vector<Point2>& pts) {
  static const std::vector<CellIndex> kNoCells;
  for (size_t i = 1; i < pts.size(); ++i) Segment(pts[i], SegmentKind::kTransition, -1, kNoCells);
}

void TourPathWriter::Cover(Point2 to, double heading, int tag) {
  heading_ = heading;
  at_ = to;
  path_->push_back({at_.x, at_.y, heading_, SegmentKind::kCoverage, tag});
}

void TourPathWriter::Segment(Point2 to, SegmentKind kind, int tag,
                             const std::vector<CellIndex>& cells) {
  const double dx = to.x - at_.x, dy = to.y - at_.y;
  const bool coverage = kind == SegmentKind::kCoverage;
  const bool degenerate = std::hypot(dx, dy) < kMinSegmentM;
  if (degenerate && !coverage) return;
  if (!degenerate) heading_ = std::atan2(dy, dx);
  at_ = to;
  path_->push_back({at_.x, at_.y, heading_, kind, coverage ? tag : -1});
  if (coverage) sweeps_->push_back({static_cast<int>(path_->size()) - 1, cells});
}

absl::Status ElementTourModel::BuildTable(const Grid& drive, std::vector<CellIndex> endpoints,
                                          const StopToken& stop, int num_threads) {
  table_started_ = absl::Now();
  ASSIGN_OR_RETURN(own_table_, TransitionTable::BuildForEndpoints(drive, std::move(endpoints), stop,
                                                                  num_threads));
  grid_ = &drive;
  table_ = own_table_.get();
  return absl::OkStatus();
}

void ElementTourModel::UseTable(const Grid& drive, const TransitionTable& table) {
  table_started_ = absl::Now();
  grid_ = &drive;
  table_ = &table;
}

void ElementTourModel::SetPoses(const Pose2& start, std::optional<Pose2> end,
                                std::shared_ptr<const MotionCost> motion) {
  start_ = start;
  has_end_ = end.has_value();
  end_ = end.value_or(start);
  motion_ = std::move(motion);
}

absl::Status ElementTourModel::RoutePoses(const StopToken& stop, const char* start_name,
                                          const char* end_name) {
  ASSIGN_OR_RETURN(const CellIndex start_cell, JoinCell(*grid_, start_, "start"));
  ASSIGN_OR_RETURN(const CellIndex end_cell, JoinCell(*grid_, end_, "end"));
  const int n = num_vertices();
  AnyAngleSearch search(*grid_);
  if (!search.Run(start_cell, stop)) {
    return absl::DeadlineExceededError(absl::StrCat("stopped while routing from the ", start_name));
  }
  start_paths_.resize(n);
  from_start_.resize(n);
  for (int v = 0; v < n; ++v) {
    const CellIndex entry = table_->endpoint(v);
    if (!search.Reached(entry)) return Unreachable(element_of(v));
    start_paths_[v] = PosePath(*grid_, start_, search.PathTo(entry));
    from_start_[v] = motion_->Polyline(start_paths_[v], start_.theta, variants_[v].heading_in) +
                     variants_[v].traverse;
  }
  // Without an end pose the search from the start serves the way back too.
  if (has_end_ && !search.Run(end_cell, stop)) {
    return absl::DeadlineExceededError(absl::StrCat("stopped while routing to the ", end_name));
  }
  end_paths_.resize(n);
  to_end_.resize(n);
  for (int u = 0; u < n; ++u) {
    const CellIndex exit = table_->endpoint(u ^ 1);
    if (!search.Reached(exit)) {
      to_end_[u] = std::numeric_limits<double>::infinity();
      continue;
    }
    // Any-angle paths are symmetric: reverse end -> exit.
    std::vector<Point2> pts = PosePath(*grid_, end_, search.PathTo(exit));
    std::reverse(pts.begin(), pts.end());
    end_paths_[u] = std::move(pts);
    to_end_[u] = motion_->Polyline(end_paths_[u], variants_[u].heading_out, std::nullopt);
  }
  transitions_ms_ = absl::ToDoubleMilliseconds(absl::Now() - table_started_);
  return absl::OkStatus();
}

double ElementTourModel::TransitionPoints(int u, int v, std::vector<Point2>* pts) const {
  thread_local std::vector<CellIndex> cells;
  thread_local std::vector<Point2> back;
  const double heading_out = variants_[u].heading_out, heading_in = variants_[v].heading_in;
  cells.clear();
  table_->AppendPath(u ^ 1, v, &cells);
  pts->clear();
  for (const CellIndex& c : cells) pts->push_back(grid_->CellCenter(c));
  double time = motion_->Polyline(*pts, heading_out, heading_in);
  // The search from v's entry found its own shortest path back: driven in
  // reverse it is as short (up to the search's tolerance) and may pass an
  // obstacle on the other side, turning less for these headings.
  if (table_->Reachable(v, u ^ 1)) {
    cells.clear();
    table_->AppendPath(v, u ^ 1, &cells);
    back.clear();
    for (auto c = cells.rbegin(); c != cells.rend(); ++c) back.push_back(grid_->CellCenter(*c));
    const double back_time = motion_->Polyline(back, heading_out, heading_in);
    if (back_time < time) {
      time = back_time;
      pts->swap(back);
    }
  }
  return time;
}

double ElementTourModel::Between(int u, int v) const {
  if (element_of(u) == element_of(v) || !table_->Reachable(u ^ 1, v)) {
    return std::numeric_limits<double>::infinity();
  }
  thread_local std::vector<Point2> pts;
  return TransitionPoints(u, v, &pts) + variants_[v].traverse;
}

void ElementTourModel::BuildPath(const std::vector<int>& vertices, std::vector<Waypoint>* path,
                                 std::vector<CoverageSweep>* sweeps) const {
  TourPathWriter writer(start_, path, sweeps);
  std::vector<Point2> pts;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const int v = vertices[i];
    if (i == 0) {
      pts = start_paths_[v];
    } else {
      TransitionPoints(vertices[i - 1], v, &pts);
    }
    writer.Transit(pts);
    DriveVariant(v, &writer);
  }
  if (!vertices.empty()) writer.Transit(end_paths_[vertices.back()]);
}

}  // namespace covplan
