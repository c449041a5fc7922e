#include "planner/boustrophedon/cell_tour.h"

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

constexpr double kInf = std::numeric_limits<double>::infinity();

// Heading of the first non-degenerate segment of `pts`, else `fallback`.
double FirstHeading(const std::vector<Point2>& pts, double fallback) {
  for (size_t i = 1; i < pts.size(); ++i) {
    const double dx = pts[i].x - pts[i - 1].x, dy = pts[i].y - pts[i - 1].y;
    if (std::hypot(dx, dy) >= kMinSegmentM) return std::atan2(dy, dx);
  }
  return fallback;
}

std::vector<Point2> Directed(const PolylineElement& e, bool backwards) {
  std::vector<Point2> pts = e.points;
  if (backwards) std::reverse(pts.begin(), pts.end());
  return pts;
}

std::vector<Point2> PosePath(const Grid& grid, const Pose2& pose,
                             const std::vector<CellIndex>& cells) {
  std::vector<Point2> pts = {{pose.x, pose.y}};
  for (const CellIndex& c : cells) pts.push_back(grid.CellCenter(c));
  return pts;
}

}  // namespace

absl::StatusOr<CellTourModel> CellTourModel::Create(
    const Grid& drive, std::vector<std::array<PolylineElement, 2>> cells, const Pose2& start,
    std::optional<Pose2> end, std::shared_ptr<const MotionCost> motion, const StopToken& stop,
    int num_threads) {
  if (cells.empty()) return absl::InvalidArgumentError("no cells to tour");
  if (motion == nullptr) return absl::InvalidArgumentError("no motion cost");
  CellTourModel m;
  m.grid_ = &drive;
  m.motion_ = std::move(motion);
  m.start_ = start;
  m.has_end_ = end.has_value();
  m.end_ = end.value_or(start);
  std::vector<CellIndex> endpoints;
  for (size_t e = 0; e < cells.size(); ++e) {
    for (const PolylineElement& el : cells[e]) {
      if (el.points.size() < 2 || el.kinds.size() + 1 != el.points.size() ||
          el.sweeps.size() != el.kinds.size() || el.tags.size() != el.kinds.size()) {
        return absl::InvalidArgumentError(absl::StrFormat("cell %d: malformed ox-plow path", e));
      }
      endpoints.push_back(el.first_cell);
      endpoints.push_back(el.last_cell);
    }
  }
  m.cells_ = std::move(cells);
  m.IndexVertices();
  const absl::Time t0 = absl::Now();
  absl::StatusOr<std::shared_ptr<const TransitionTable>> table =
      TransitionTable::BuildForEndpoints(drive, std::move(endpoints), stop, num_threads);
  if (!table.ok()) return table.status();
  m.table_ = std::move(*table);
  const int n = m.num_vertices();
  m.heading_in_.resize(n), m.heading_out_.resize(n), m.traverse_.resize(n);
  for (int v = 0; v < n; ++v) {
    const PolylineElement& el = m.Element(v);
    const bool backwards = v % 2 == 1;
    const std::vector<Point2> pts = Directed(el, backwards);
    const std::vector<Point2> rev = Directed(el, !backwards);
    const double axis =
        (el.first_cell.row == el.last_cell.row ? 0.0 : M_PI / 2) + (backwards ? M_PI : 0.0);
    m.heading_in_[v] = FirstHeading(pts, axis);
    m.heading_out_[v] = std::fmod(FirstHeading(rev, axis + M_PI) + M_PI, 2 * M_PI);
    m.traverse_[v] = m.motion_->Polyline(pts, m.heading_in_[v], std::nullopt);
  }
  absl::StatusOr<CellIndex> start_cell = JoinCell(drive, m.start_, "start");
  if (!start_cell.ok()) return start_cell.status();
  absl::StatusOr<CellIndex> end_cell = JoinCell(drive, m.end_, "end");
  if (!end_cell.ok()) return end_cell.status();
  AnyAngleSearch search(drive);
  if (!search.Run(*start_cell, stop))
    return absl::DeadlineExceededError("stopped while routing from the start");
  m.start_paths_.resize(n), m.from_start_.resize(n);
  for (int v = 0; v < n; ++v) {
    const CellIndex entry = m.table_->endpoint(v);
    if (!search.Reached(entry)) {
      return absl::FailedPreconditionError(
          absl::StrFormat("cell %d cannot be reached from the start", v / 4));
    }
    m.start_paths_[v] = PosePath(drive, m.start_, search.PathTo(entry));
    m.from_start_[v] =
        m.motion_->Polyline(m.start_paths_[v], m.start_.theta, m.heading_in_[v]) + m.traverse_[v];
  }
  if (m.has_end_ && !search.Run(*end_cell, stop))
    return absl::DeadlineExceededError("stopped while routing to the end");
  m.end_paths_.resize(n), m.to_end_.resize(n);
  for (int u = 0; u < n; ++u) {
    const CellIndex exit = m.table_->endpoint(u ^ 1);
    if (!search.Reached(exit)) {
      m.to_end_[u] = kInf;
      continue;
    }
    std::vector<Point2> pts = PosePath(drive, m.end_, search.PathTo(exit));
    std::reverse(pts.begin(), pts.end());
    m.to_end_[u] = m.motion_->Polyline(pts, m.heading_out_[u], std::nullopt);
    m.end_paths_[u] = std::move(pts);
  }
  m.transitions_ms_ = absl::ToDoubleMilliseconds(absl::Now() - t0);
  return m;
}

void CellTourModel::TransitionPoints(int u, int v, std::vector<Point2>* pts) const {
  thread_local std::vector<CellIndex> cells;
  cells.clear();
  table_->AppendPath(u ^ 1, v, &cells);
  pts->clear();
  for (const CellIndex& c : cells) pts->push_back(grid_->CellCenter(c));
}

double CellTourModel::Between(int u, int v) const {
  if (u / 4 == v / 4 || !table_->Reachable(u ^ 1, v)) return kInf;
  thread_local std::vector<Point2> pts;
  TransitionPoints(u, v, &pts);
  return motion_->Polyline(pts, heading_out_[u], heading_in_[v]) + traverse_[v];
}

void CellTourModel::BuildPath(const std::vector<int>& vertices, std::vector<Waypoint>* path,
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
    writer.Drive(Element(v), v % 2 == 0, heading_in_[v]);
  }
  if (!vertices.empty()) writer.Transit(end_paths_[vertices.back()]);
}

}  // namespace covplan
