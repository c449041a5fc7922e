#include "planner/stc/stc_walk.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"

namespace covplan {
namespace {

constexpr int kDr[4] = {0, 1, 0, -1};
constexpr int kDc[4] = {1, 0, -1, 0};

// Shortest 4-neighbour paths on the drive grid, reusing its buffers.
class Bridge {
 public:
  explicit Bridge(const Grid& grid)
      : grid_(grid), stamp_(grid.size(), 0), parent_(grid.size(), -1) {}

  // Cells after `from` up to and including `to`; empty when unreachable.
  std::vector<CellIndex> Path(CellIndex from, CellIndex to) {
    ++round_;
    const int64_t src = grid_.Index(from.row, from.col), dst = grid_.Index(to.row, to.col);
    queue_.clear();
    queue_.push_back(src);
    stamp_[src] = round_;
    for (size_t head = 0; head < queue_.size() && stamp_[dst] != round_; ++head) {
      const CellIndex c = grid_.FromIndex(queue_[head]);
      for (int d = 0; d < 4; ++d) {
        if (!grid_.Passable(c.row, c.col, kDr[d], kDc[d])) continue;
        const int64_t n = grid_.Index(c.row + kDr[d], c.col + kDc[d]);
        if (stamp_[n] == round_) continue;
        stamp_[n] = round_;
        parent_[n] = queue_[head];
        queue_.push_back(n);
      }
    }
    std::vector<CellIndex> path;
    if (stamp_[dst] != round_) return path;
    for (int64_t v = dst; v != src; v = parent_[v]) path.push_back(grid_.FromIndex(v));
    return {path.rbegin(), path.rend()};
  }

 private:
  const Grid& grid_;
  std::vector<uint32_t> stamp_;
  std::vector<int64_t> parent_;
  std::vector<int64_t> queue_;
  uint32_t round_ = 0;
};

}  // namespace

absl::StatusOr<StcWalk> WalkInOrder(const Grid& drive, const Grid& cover, const std::vector<CellIndex>& order,
                                    CellIndex start, CellIndex end, const StopToken& stop) {
  if (!drive.IsFree(start) || !drive.IsFree(end)) return absl::InternalError("STC walk outside the drive grid");
  auto is_target = [&](CellIndex c) { return drive.IsFree(c) && cover.IsFree(c); };
  StcWalk walk;
  walk.start = start;
  std::vector<uint8_t> covered(drive.size(), 0), entered(drive.size(), 0);
  auto index = [&](CellIndex c) { return drive.Index(c.row, c.col); };
  walk.start_covers = is_target(start);
  if (walk.start_covers) {
    covered[index(start)] = 1;
    ++walk.covered_cells;
  }
  entered[index(start)] = 1;
  Bridge bridge(drive);
  CellIndex at = start;
  auto step = [&](CellIndex to) {
    const bool fresh = is_target(to) && !covered[index(to)];
    walk.steps.push_back(to);
    walk.covers.push_back(fresh);
    if (fresh) {
      covered[index(to)] = 1;
      ++walk.covered_cells;
    }
    at = to;
  };
  int64_t bridges = 0;
  for (const CellIndex& next : order) {
    if (!is_target(next) || covered[index(next)]) continue;
    const bool adjacent = std::abs(next.row - at.row) + std::abs(next.col - at.col) == 1 &&
                          drive.Passable(at.row, at.col, next.row - at.row, next.col - at.col);
    if (adjacent) {
      step(next);
      continue;
    }
    if (++bridges % 256 == 0 && stop.ShouldStop()) {
      return absl::DeadlineExceededError("stopped while walking the STC order");
    }
    const std::vector<CellIndex> path = bridge.Path(at, next);
    if (path.empty()) {
      return absl::InternalError(absl::StrFormat("STC: cell (%d, %d) cannot be reached from (%d, %d)",
                                                 next.row, next.col, at.row, at.col));
    }
    for (const CellIndex& c : path) step(c);
  }
  walk.coverage_steps = static_cast<int64_t>(walk.steps.size());
  while (walk.coverage_steps > 0 && !walk.covers[walk.coverage_steps - 1]) --walk.coverage_steps;
  for (int64_t i = 0; i < walk.coverage_steps; ++i) {
    walk.extra_moves += !walk.covers[i];
    uint8_t& e = entered[index(walk.steps[i])];
    if (e == 1) ++walk.cells_covered_twice;
    if (e < 2) ++e;
  }
  if (at != end) {
    const std::vector<CellIndex> path = bridge.Path(at, end);
    if (path.empty()) return absl::InternalError("STC: the end cell cannot be reached");
    for (const CellIndex& c : path) step(c);
  }
  return walk;
}

void AppendWalk(const Grid& drive, const StcWalk& walk, const std::optional<Pose2>& start_pose,
                const std::optional<Pose2>& end_pose, const std::function<int(CellIndex)>& tag,
                CoveragePlan* plan) {
  std::vector<Waypoint>& path = plan->path;
  const Point2 s = drive.CellCenter(walk.start);
  auto heading_to = [](Point2 a, Point2 b, double fallback) {
    return (a.x == b.x && a.y == b.y) ? fallback : std::atan2(b.y - a.y, b.x - a.x);
  };
  const double first_heading =
      walk.steps.empty() ? (start_pose ? start_pose->theta : 0.0)
                         : heading_to(s, drive.CellCenter(walk.steps[0]), 0.0);
  if (start_pose) {
    path.push_back({start_pose->x, start_pose->y, start_pose->theta, SegmentKind::kStart, -1});
    if (start_pose->x != s.x || start_pose->y != s.y) {
      path.push_back({s.x, s.y, heading_to({start_pose->x, start_pose->y}, s, start_pose->theta),
                      SegmentKind::kTransition, -1});
    }
  } else {
    path.push_back({s.x, s.y, first_heading, SegmentKind::kStart, -1});
  }
  // The start cell is swept by the first segment (it starts at its centre):
  // make that segment a coverage one when the start cell is to cover.
  const bool start_fresh = walk.start_covers;
  CellIndex prev = walk.start;
  size_t i = 0;
  if (walk.steps.empty() && start_fresh) {
    // One cell to cover: a zero-length coverage segment on it.
    path.push_back({s.x, s.y, path.back().theta, SegmentKind::kCoverage, tag(walk.start)});
    plan->sweeps.push_back({static_cast<int>(path.size()) - 1, {walk.start}});
  }
  while (i < walk.steps.size()) {
    const bool covers = walk.covers[i] || (i == 0 && start_fresh);
    const int dr = walk.steps[i].row - prev.row, dc = walk.steps[i].col - prev.col;
    CoverageSweep sweep;
    if (covers && i == 0 && start_fresh) sweep.cells.push_back(walk.start);
    size_t j = i;
    while (j < walk.steps.size() && walk.steps[j].row - (j == 0 ? walk.start : walk.steps[j - 1]).row == dr &&
           walk.steps[j].col - (j == 0 ? walk.start : walk.steps[j - 1]).col == dc &&
           (walk.covers[j] || (j == 0 && start_fresh)) == covers) {
      if (walk.covers[j]) sweep.cells.push_back(walk.steps[j]);
      ++j;
    }
    const Point2 p = drive.CellCenter(walk.steps[j - 1]);
    path.push_back({p.x, p.y, std::atan2(static_cast<double>(dr), static_cast<double>(dc)),
                    covers ? SegmentKind::kCoverage : SegmentKind::kTransition,
                    covers ? tag(walk.steps[j - 1]) : -1});
    if (covers) {
      sweep.waypoint = static_cast<int>(path.size()) - 1;
      plan->sweeps.push_back(std::move(sweep));
    }
    prev = walk.steps[j - 1];
    i = j;
  }
  if (end_pose) {
    const Point2 e = drive.CellCenter(prev);
    if (end_pose->x != e.x || end_pose->y != e.y) {
      path.push_back({end_pose->x, end_pose->y, heading_to(e, {end_pose->x, end_pose->y}, path.back().theta),
                      SegmentKind::kTransition, -1});
    }
  }
}

}  // namespace covplan
