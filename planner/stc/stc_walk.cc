#include "planner/stc/stc_walk.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

constexpr int kDr[4] = {0, 1, 0, -1};
constexpr int kDc[4] = {1, 0, -1, 0};

}  // namespace

StcWalker::StcWalker(const Grid& shape, World world, CellIndex start)
    : shape_(shape),
      world_(std::move(world)),
      at_(start),
      covered_(shape.size(), 0),
      stamp_(shape.size(), 0),
      parent_(shape.size(), -1) {
  walk_.start = start;
  walk_.start_covers = world_.to_cover(start);
  if (walk_.start_covers) {
    covered_[shape_.Index(start.row, start.col)] = 1;
    walk_.covered_cells = 1;
  }
}

absl::Status StcWalker::Step(CellIndex to) {
  const int64_t i = shape_.Index(to.row, to.col);
  const bool fresh = world_.to_cover(to) && !covered_[i];
  walk_.steps.push_back(to);
  walk_.covers.push_back(fresh);
  if (fresh) {
    covered_[i] = 1;
    ++walk_.covered_cells;
  }
  at_ = to;
  return world_.on_step ? world_.on_step(to) : absl::OkStatus();
}

std::vector<CellIndex> StcWalker::Path(CellIndex from, CellIndex to) {
  ++round_;
  const int64_t src = shape_.Index(from.row, from.col), dst = shape_.Index(to.row, to.col);
  queue_.clear();
  queue_.push_back(src);
  stamp_[src] = round_;
  for (size_t head = 0; head < queue_.size() && stamp_[dst] != round_; ++head) {
    const CellIndex c = shape_.FromIndex(queue_[head]);
    for (int d = 0; d < 4; ++d) {
      const CellIndex n{c.row + kDr[d], c.col + kDc[d]};
      if (!shape_.InBounds(n.row, n.col) || !world_.may_enter(n) ||
          !world_.passable(c, kDr[d], kDc[d]))
        continue;
      const int64_t ni = shape_.Index(n.row, n.col);
      if (stamp_[ni] == round_) continue;
      stamp_[ni] = round_;
      parent_[ni] = queue_[head];
      queue_.push_back(ni);
    }
  }
  std::vector<CellIndex> path;
  if (stamp_[dst] != round_) return path;
  for (int64_t v = dst; v != src; v = parent_[v]) path.push_back(shape_.FromIndex(v));
  return {path.rbegin(), path.rend()};
}

absl::Status StcWalker::Excursion(CellIndex from) {
  // Depth first over orphans, out and back; an explicit stack, since a chain
  // of orphans can be as long as the map is large.
  struct Frame {
    CellIndex cell;
    int next_dir;
  };
  std::vector<Frame> stack = {{from, 0}};
  while (!stack.empty()) {
    Frame& f = stack.back();
    if (f.next_dir == 4) {
      stack.pop_back();
      if (!stack.empty()) RETURN_IF_ERROR(Step(stack.back().cell));  // back out
      continue;
    }
    const int d = f.next_dir++;
    const CellIndex c = f.cell;
    const CellIndex o{c.row + kDr[d], c.col + kDc[d]};
    if (!shape_.InBounds(o.row, o.col) || !world_.may_enter(o) || !world_.orphan(o) || covered(o) ||
        !world_.passable(c, kDr[d], kDc[d])) {
      continue;
    }
    RETURN_IF_ERROR(Step(o));
    stack.push_back({o, 0});
  }
  return absl::OkStatus();
}

absl::Status StcWalker::Excursions() { return Excursion(at_); }

absl::Status StcWalker::Visit(CellIndex next, const StopToken& stop) {
  if (covered(next)) return absl::OkStatus();
  // An orphan touching both this cell and the next is swept on the way.
  int via = -1;
  for (int d = 0; d < 4 && via < 0; ++d) {
    const CellIndex o{at_.row + kDr[d], at_.col + kDc[d]};
    if (!shape_.InBounds(o.row, o.col) || !world_.may_enter(o) || !world_.orphan(o) || covered(o) ||
        !world_.passable(at_, kDr[d], kDc[d])) {
      continue;
    }
    const int dr = next.row - o.row, dc = next.col - o.col;
    if (std::abs(dr) + std::abs(dc) == 1 && world_.passable(o, dr, dc)) via = d;
  }
  const CellIndex here = at_;
  for (int d = 0; d < 4; ++d) {
    if (d == via) continue;
    const CellIndex o{here.row + kDr[d], here.col + kDc[d]};
    if (!shape_.InBounds(o.row, o.col) || !world_.may_enter(o) || !world_.orphan(o) || covered(o) ||
        !world_.passable(here, kDr[d], kDc[d])) {
      continue;
    }
    RETURN_IF_ERROR(Step(o));
    RETURN_IF_ERROR(Excursion(o));
    RETURN_IF_ERROR(Step(here));
  }
  if (via >= 0) {
    const CellIndex o{here.row + kDr[via], here.col + kDc[via]};
    if (!covered(o)) {
      RETURN_IF_ERROR(Step(o));
      RETURN_IF_ERROR(Excursion(o));
    }
  }
  if (covered(next)) return absl::OkStatus();
  const bool adjacent = std::abs(next.row - at_.row) + std::abs(next.col - at_.col) == 1 &&
                        world_.passable(at_, next.row - at_.row, next.col - at_.col);
  if (adjacent) return Step(next);
  if (++bridges_ % 256 == 0 && stop.ShouldStop()) {
    return absl::DeadlineExceededError("stopped while walking the STC order");
  }
  const std::vector<CellIndex> path = Path(at_, next);
  if (path.empty()) return absl::NotFoundError("no known path to the next sub-cell");
  for (const CellIndex& c : path) RETURN_IF_ERROR(Step(c));
  return absl::OkStatus();
}

absl::Status StcWalker::SweepRemaining(const std::vector<CellIndex>& pending,
                                       const StopToken& stop) {
  // Nearest first: one BFS from the robot to the closest unswept pending cell.
  std::vector<uint8_t> want(shape_.size(), 0);
  for (const CellIndex& c : pending) want[shape_.Index(c.row, c.col)] = 1;
  while (true) {
    if (stop.ShouldStop())
      return absl::DeadlineExceededError("stopped while sweeping the last STC cells");
    ++round_;
    const int64_t src = shape_.Index(at_.row, at_.col);
    queue_.clear();
    queue_.push_back(src);
    stamp_[src] = round_;
    int64_t found = -1;
    for (size_t head = 0; head < queue_.size() && found < 0; ++head) {
      const CellIndex c = shape_.FromIndex(queue_[head]);
      for (int d = 0; d < 4 && found < 0; ++d) {
        const CellIndex n{c.row + kDr[d], c.col + kDc[d]};
        if (!shape_.InBounds(n.row, n.col) || !world_.may_enter(n) ||
            !world_.passable(c, kDr[d], kDc[d]))
          continue;
        const int64_t ni = shape_.Index(n.row, n.col);
        if (stamp_[ni] == round_) continue;
        stamp_[ni] = round_;
        parent_[ni] = queue_[head];
        queue_.push_back(ni);
        if (want[ni] && !covered_[ni]) found = ni;
      }
    }
    if (found < 0) break;
    std::vector<CellIndex> path;
    for (int64_t v = found; v != src; v = parent_[v]) path.push_back(shape_.FromIndex(v));
    for (auto it = path.rbegin(); it != path.rend(); ++it) RETURN_IF_ERROR(Step(*it));
    RETURN_IF_ERROR(Excursions());
  }
  for (const CellIndex& c : pending) {
    if (!covered(c)) return absl::NotFoundError("no known path to the remaining cells");
  }
  return absl::OkStatus();
}

absl::Status StcWalker::GoTo(CellIndex end) {
  if (at_ == end) return absl::OkStatus();
  const std::vector<CellIndex> path = Path(at_, end);
  if (path.empty()) return absl::NotFoundError("no known path to the end cell");
  for (const CellIndex& c : path) RETURN_IF_ERROR(Step(c));
  return absl::OkStatus();
}

StcWalk StcWalker::Finish() const {
  StcWalk walk = walk_;
  walk.coverage_steps = static_cast<int64_t>(walk.steps.size());
  while (walk.coverage_steps > 0 && !walk.covers[walk.coverage_steps - 1]) --walk.coverage_steps;
  std::vector<uint8_t> entered(shape_.size(), 0);
  entered[shape_.Index(walk.start.row, walk.start.col)] = 1;
  for (int64_t i = 0; i < walk.coverage_steps; ++i) {
    walk.extra_moves += !walk.covers[i];
    uint8_t& e = entered[shape_.Index(walk.steps[i].row, walk.steps[i].col)];
    if (e == 1) ++walk.cells_covered_twice;
    if (e < 2) ++e;
  }
  return walk;
}

absl::StatusOr<StcWalk> WalkForest(const Grid& drive, const Grid& cover,
                                   const std::vector<std::vector<CellIndex>>& rings,
                                   const std::vector<uint8_t>& orphan, CellIndex start,
                                   CellIndex end, const StopToken& stop) {
  if (!drive.IsFree(start) || !drive.IsFree(end))
    return absl::InternalError("STC walk outside the drive grid");
  auto to_cover = [&](CellIndex c) { return drive.IsFree(c) && cover.IsFree(c); };
  StcWalker::World world;
  world.may_enter = [&](CellIndex c) { return drive.IsFree(c); };
  world.passable = [&](CellIndex c, int dr, int dc) {
    return drive.Passable(c.row, c.col, dr, dc);
  };
  world.to_cover = to_cover;
  world.orphan = [&](CellIndex c) {
    return !orphan.empty() && orphan[drive.Index(c.row, c.col)] != 0;
  };
  StcWalker walker(drive, std::move(world), start);
  auto internal = [](const absl::Status& s) {
    return absl::IsNotFound(s) ? absl::InternalError(absl::StrCat("STC: ", s.message())) : s;
  };
  // Which ring (and where in it) each free tree cell is.
  std::vector<int32_t> tree_of(drive.size(), -1), index_in(drive.size(), -1);
  for (size_t t = 0; t < rings.size(); ++t) {
    for (size_t k = 0; k < rings[t].size(); ++k) {
      const CellIndex c = rings[t][k];
      if (!drive.IsFree(c)) continue;
      tree_of[drive.Index(c.row, c.col)] = static_cast<int32_t>(t);
      index_in[drive.Index(c.row, c.col)] = static_cast<int32_t>(k);
    }
  }
  std::vector<uint8_t> walked(rings.size(), 0);
  struct Frame {
    int tree;
    size_t first;
    size_t k;
  };
  std::vector<Frame> stack;
  auto begin = [&](int tree, CellIndex at) {
    walked[tree] = 1;
    stack.push_back({tree, static_cast<size_t>(index_in[drive.Index(at.row, at.col)]), 0});
  };
  constexpr int kDr[4] = {0, 1, 0, -1}, kDc[4] = {1, 0, -1, 0};
  // A tree next to the robot not walked yet: walk it from there.
  auto splice = [&]() {
    const CellIndex at = walker.at();
    for (int d = 0; d < 4; ++d) {
      const CellIndex n{at.row + kDr[d], at.col + kDc[d]};
      if (!drive.IsFree(n) || !drive.Passable(at.row, at.col, kDr[d], kDc[d])) continue;
      const int t = tree_of[drive.Index(n.row, n.col)];
      if (t < 0 || walked[t]) continue;
      begin(t, n);
      return true;
    }
    return false;
  };
  auto run = [&]() -> absl::Status {
    while (!stack.empty()) {
      Frame& f = stack.back();
      const std::vector<CellIndex>& ring = rings[f.tree];
      if (f.k == ring.size()) {
        stack.pop_back();
        continue;
      }
      const CellIndex c = ring[(f.first + f.k++) % ring.size()];
      if (!to_cover(c)) continue;
      RETURN_IF_ERROR(walker.Visit(c, stop));
      splice();
    }
    return absl::OkStatus();
  };
  const int first_tree = tree_of[drive.Index(start.row, start.col)];
  absl::Status s;
  if (first_tree >= 0) {
    begin(first_tree, start);
    s = run();
    if (!s.ok()) return internal(s);
  }
  // Trees never met: nearest first (BFS over the drive grid).
  std::vector<uint32_t> seen(drive.size(), 0);
  std::vector<int64_t> queue;
  for (uint32_t round = 1;; ++round) {
    if (stop.ShouldStop())
      return absl::DeadlineExceededError("stopped while walking the STC forest");
    queue.assign(1, drive.Index(walker.at().row, walker.at().col));
    seen[queue[0]] = round;
    int64_t found = -1;
    for (size_t head = 0; head < queue.size() && found < 0; ++head) {
      const int64_t v = queue[head];
      if (tree_of[v] >= 0 && !walked[tree_of[v]]) found = v;
      const CellIndex c = drive.FromIndex(v);
      for (int d = 0; d < 4; ++d) {
        if (!drive.Passable(c.row, c.col, kDr[d], kDc[d])) continue;
        const int64_t n = drive.Index(c.row + kDr[d], c.col + kDc[d]);
        if (seen[n] != round) seen[n] = round, queue.push_back(n);
      }
    }
    if (found < 0) break;
    begin(tree_of[found], drive.FromIndex(found));
    s = run();
    if (!s.ok()) return internal(s);
  }
  s = walker.Excursions();
  if (!s.ok()) return internal(s);
  std::vector<CellIndex> pending;
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (!orphan.empty() && orphan[i]) pending.push_back(drive.FromIndex(i));
  }
  s = walker.SweepRemaining(pending, stop);
  if (!s.ok()) return internal(s);
  s = walker.GoTo(end);
  if (!s.ok()) return internal(s);
  return walker.Finish();
}

void AppendWalk(const Grid& drive, const StcWalk& walk, const std::optional<Pose2>& start_pose,
                const std::optional<Pose2>& end_pose, const std::function<int(CellIndex)>& tag,
                CoveragePlan* plan) {
  std::vector<Waypoint>& path = plan->path;
  const Point2 s = drive.CellCenter(walk.start);
  auto heading_to = [](Point2 a, Point2 b, double fallback) {
    return (a.x == b.x && a.y == b.y) ? fallback : std::atan2(b.y - a.y, b.x - a.x);
  };
  const double first_heading = walk.steps.empty()
                                   ? (start_pose ? start_pose->theta : 0.0)
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
    while (j < walk.steps.size() &&
           walk.steps[j].row - (j == 0 ? walk.start : walk.steps[j - 1]).row == dr &&
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
      path.push_back({end_pose->x, end_pose->y,
                      heading_to(e, {end_pose->x, end_pose->y}, path.back().theta),
                      SegmentKind::kTransition, -1});
    }
  }
}

}  // namespace covplan
