#include "planner/tour/polyline_tour.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

// Heading of the first non-degenerate segment of `pts` (forwards), or the
// element's axis for a single point.
double FirstHeading(const std::vector<Point2>& pts, double fallback) {
  for (size_t i = 1; i < pts.size(); ++i) {
    const double dx = pts[i].x - pts[i - 1].x, dy = pts[i].y - pts[i - 1].y;
    if (std::hypot(dx, dy) >= kMinSegmentM) return std::atan2(dy, dx);
  }
  return fallback;
}

std::vector<Point2> Reversed(std::vector<Point2> pts) {
  std::reverse(pts.begin(), pts.end());
  return pts;
}

std::vector<Point2> PosePath(const Grid& grid, const Pose2& pose,
                             const std::vector<CellIndex>& cells) {
  std::vector<Point2> pts = {{pose.x, pose.y}};
  for (const CellIndex& c : cells) pts.push_back(grid.CellCenter(c));
  return pts;
}

}  // namespace

PolylineElement RankElement(const Grid& grid, CellIndex first, CellIndex last, int tag) {
  PolylineElement e;
  e.kind = TourElementKind::kRank;
  e.points = {grid.CellCenter(first), grid.CellCenter(last)};
  e.kinds = {SegmentKind::kCoverage};
  std::vector<CellIndex> cells;
  const bool h = first.row == last.row;
  const int n = h ? last.col - first.col + 1 : last.row - first.row + 1;
  for (int k = 0; k < n; ++k)
    cells.push_back(h ? CellIndex{first.row, first.col + k} : CellIndex{first.row + k, first.col});
  e.sweeps = {std::move(cells)};
  e.tags = {tag};
  e.first_cell = first;
  e.last_cell = last;
  return e;
}

absl::StatusOr<PolylineTourModel> PolylineTourModel::Create(
    const Grid& drive, std::vector<PolylineElement> elements, const Pose2& start,
    std::optional<Pose2> end, std::shared_ptr<const MotionCost> motion, const StopToken& stop,
    int num_threads) {
  if (elements.empty()) return absl::InvalidArgumentError("no tour elements");
  if (motion == nullptr) return absl::InvalidArgumentError("no motion cost");
  PolylineTourModel m;
  m.grid_ = &drive;
  m.motion_ = std::move(motion);
  m.start_ = start;
  m.has_end_ = end.has_value();
  m.end_ = end.value_or(start);
  std::vector<CellIndex> endpoints;
  for (size_t e = 0; e < elements.size(); ++e) {
    const PolylineElement& el = elements[e];
    if (el.points.size() < 2 || el.kinds.size() + 1 != el.points.size() ||
        el.sweeps.size() != el.kinds.size() || el.tags.size() != el.kinds.size()) {
      return absl::InvalidArgumentError(absl::StrFormat("tour element %d is malformed", e));
    }
    endpoints.push_back(el.first_cell);
    endpoints.push_back(el.last_cell);
  }
  m.elements_ = std::move(elements);
  m.IndexVertices();
  const absl::Time t0 = absl::Now();
  absl::StatusOr<std::shared_ptr<const TransitionTable>> table =
      TransitionTable::BuildForEndpoints(drive, std::move(endpoints), stop, num_threads);
  if (!table.ok()) return table.status();
  m.table_ = std::move(*table);
  const int n = m.num_vertices();
  m.heading_in_.resize(n);
  m.heading_out_.resize(n);
  m.traverse_.resize(n);
  for (int e = 0; e < m.num_elements(); ++e) {
    const std::vector<Point2>& fwd = m.elements_[e].points;
    const std::vector<Point2> bwd = Reversed(fwd);
    const double axis =
        m.elements_[e].first_cell.row == m.elements_[e].last_cell.row ? 0.0 : M_PI / 2;
    m.heading_in_[2 * e] = FirstHeading(fwd, axis);
    m.heading_out_[2 * e] = std::fmod(FirstHeading(bwd, axis + M_PI) + M_PI, 2 * M_PI);
    m.heading_in_[2 * e + 1] = FirstHeading(bwd, axis + M_PI);
    m.heading_out_[2 * e + 1] = std::fmod(FirstHeading(fwd, axis) + M_PI, 2 * M_PI);
    m.traverse_[2 * e] = m.motion_->Polyline(fwd, m.heading_in_[2 * e], std::nullopt);
    m.traverse_[2 * e + 1] = m.motion_->Polyline(bwd, m.heading_in_[2 * e + 1], std::nullopt);
  }
  absl::StatusOr<CellIndex> start_cell = JoinCell(drive, m.start_, "start");
  if (!start_cell.ok()) return start_cell.status();
  absl::StatusOr<CellIndex> end_cell = JoinCell(drive, m.end_, "end");
  if (!end_cell.ok()) return end_cell.status();
  AnyAngleSearch search(drive);
  if (!search.Run(*start_cell, stop))
    return absl::DeadlineExceededError("stopped while routing from the start");
  m.start_paths_.resize(n);
  m.from_start_.resize(n);
  for (int v = 0; v < n; ++v) {
    const CellIndex entry = m.table_->endpoint(EntryEndpoint(v));
    if (!search.Reached(entry)) {
      return absl::FailedPreconditionError(
          absl::StrFormat("tour element %d cannot be reached from the start", v / 2));
    }
    m.start_paths_[v] = PosePath(drive, m.start_, search.PathTo(entry));
    m.from_start_[v] =
        m.motion_->Polyline(m.start_paths_[v], m.start_.theta, m.heading_in_[v]) + m.traverse_[v];
  }
  if (m.has_end_ && !search.Run(*end_cell, stop)) {
    return absl::DeadlineExceededError("stopped while routing to the end");
  }
  m.end_paths_.resize(n);
  m.to_end_.resize(n);
  for (int u = 0; u < n; ++u) {
    const CellIndex exit = m.table_->endpoint(ExitEndpoint(u));
    if (!search.Reached(exit)) {
      m.to_end_[u] = std::numeric_limits<double>::infinity();
      continue;
    }
    std::vector<Point2> pts = PosePath(drive, m.end_, search.PathTo(exit));
    std::reverse(pts.begin(), pts.end());
    m.end_paths_[u] = std::move(pts);
    m.to_end_[u] = m.motion_->Polyline(m.end_paths_[u], m.heading_out_[u], std::nullopt);
  }
  m.transitions_ms_ = absl::ToDoubleMilliseconds(absl::Now() - t0);
  return m;
}

void PolylineTourModel::TransitionPoints(int u, int v, std::vector<Point2>* pts) const {
  thread_local std::vector<CellIndex> cells;
  cells.clear();
  table_->AppendPath(ExitEndpoint(u), EntryEndpoint(v), &cells);
  pts->clear();
  for (const CellIndex& c : cells) pts->push_back(grid_->CellCenter(c));
}

double PolylineTourModel::Between(int u, int v) const {
  if (u / 2 == v / 2) return std::numeric_limits<double>::infinity();
  if (!table_->Reachable(ExitEndpoint(u), EntryEndpoint(v)))
    return std::numeric_limits<double>::infinity();
  thread_local std::vector<Point2> pts;
  TransitionPoints(u, v, &pts);
  return motion_->Polyline(pts, HeadingOut(u), HeadingIn(v)) + traverse_[v];
}

void PolylineTourModel::BuildPath(const std::vector<int>& vertices, std::vector<Waypoint>* path,
                                  std::vector<CoverageSweep>* sweeps) const {
  PolylinePathWriter writer(start_, path, sweeps);
  std::vector<Point2> pts;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const int v = vertices[i];
    if (i == 0) {
      pts = start_paths_[v];
    } else {
      TransitionPoints(vertices[i - 1], v, &pts);
    }
    writer.Transit(pts);
    writer.Drive(elements_[v / 2], v % 2 == 0, HeadingIn(v));
  }
  if (!vertices.empty()) writer.Transit(end_paths_[vertices.back()]);
}

PolylinePathWriter::PolylinePathWriter(const Pose2& start, std::vector<Waypoint>* path,
                                       std::vector<CoverageSweep>* sweeps)
    : at_{start.x, start.y}, heading_(start.theta), path_(path), sweeps_(sweeps) {
  path_->push_back({at_.x, at_.y, heading_, SegmentKind::kStart, -1});
}

void PolylinePathWriter::Transit(const std::vector<Point2>& pts) {
  for (size_t i = 1; i < pts.size(); ++i) {
    const double dx = pts[i].x - at_.x, dy = pts[i].y - at_.y;
    if (std::hypot(dx, dy) < kMinSegmentM) continue;
    heading_ = std::atan2(dy, dx);
    at_ = pts[i];
    path_->push_back({at_.x, at_.y, heading_, SegmentKind::kTransition, -1});
  }
}

void PolylinePathWriter::Drive(const PolylineElement& el, bool forward, double heading_in) {
  const int segs = static_cast<int>(el.kinds.size());
  heading_ = heading_in;
  for (int k = 0; k < segs; ++k) {
    const int s = forward ? k : segs - 1 - k;
    const Point2 to = forward ? el.points[s + 1] : el.points[s];
    const double dx = to.x - at_.x, dy = to.y - at_.y;
    const bool coverage = el.kinds[s] == SegmentKind::kCoverage;
    if (std::hypot(dx, dy) < kMinSegmentM && !coverage) continue;
    if (std::hypot(dx, dy) >= kMinSegmentM) heading_ = std::atan2(dy, dx);
    at_ = to;
    path_->push_back({at_.x, at_.y, heading_, el.kinds[s], coverage ? el.tags[s] : -1});
    if (coverage) sweeps_->push_back({static_cast<int>(path_->size()) - 1, el.sweeps[s]});
  }
}

}  // namespace covplan
