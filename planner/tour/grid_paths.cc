#include "planner/tour/grid_paths.h"

#include <algorithm>
#include <limits>
#include <optional>
#include <cmath>
#include <cstdlib>
#include <queue>
#include <utility>

#include "absl/strings/str_format.h"

namespace covplan {

bool LineOfSight(const Grid& grid, CellIndex a, CellIndex b) {
  int x = a.col, y = a.row;
  const int dx = b.col - a.col, dy = b.row - a.row;
  const int64_t nx = std::abs(dx), ny = std::abs(dy);
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  if (!grid.IsFree(y, x)) return false;
  // Inside cells that overlap non-free map pixels, the segment itself must
  // not touch one (a table inside two free cells blocks the line through it).
  const ObstaclePixels* px = grid.obstacle_pixels();
  const Point2 pa{a.col + 0.5, a.row + 0.5}, pb{b.col + 0.5, b.row + 0.5};
  auto pixels_clear = [&](int r, int c) {
    return px == nullptr || !px->CellDirty(r, c) || !px->SegmentBlockedInCell(r, c, pa, pb);
  };
  if (!pixels_clear(y, x)) return false;
  for (int64_t ix = 0, iy = 0; ix < nx || iy < ny;) {
    // Compare the parameters at which the segment crosses the next vertical
    // ((0.5 + ix) / nx) and horizontal ((0.5 + iy) / ny) grid line.
    const int64_t decision = (1 + 2 * ix) * ny - (1 + 2 * iy) * nx;
    if (decision == 0) {
      // Exactly through a grid corner: all four cells around it are touched,
      // and no barrier may meet the corner.
      if (!grid.Passable(y, x, 0, sx) || !grid.Passable(y, x + sx, sy, 0) ||
          !grid.Passable(y, x, sy, 0) || !grid.Passable(y + sy, x, 0, sx)) {
        return false;
      }
      if (!pixels_clear(y, x + sx) || !pixels_clear(y + sy, x)) return false;
      x += sx, y += sy, ++ix, ++iy;
    } else if (decision < 0) {
      if (!grid.Passable(y, x, 0, sx)) return false;
      x += sx, ++ix;
    } else {
      if (!grid.Passable(y, x, sy, 0)) return false;
      y += sy, ++iy;
    }
    if (!pixels_clear(y, x)) return false;
  }
  return true;
}

std::vector<int32_t> FreeComponents(const Grid& grid, int32_t* num_components) {
  std::vector<int32_t> comp(grid.size(), -1);
  int32_t next = 0;
  std::vector<int64_t> stack;
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (!grid.free_flags()[i] || comp[i] >= 0) continue;
    comp[i] = next;
    stack.push_back(i);
    while (!stack.empty()) {
      const CellIndex c = grid.FromIndex(stack.back());
      stack.pop_back();
      constexpr int kDr[4] = {1, -1, 0, 0}, kDc[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int r = c.row + kDr[k], cc = c.col + kDc[k];
        if (!grid.Passable(c.row, c.col, kDr[k], kDc[k])) continue;
        const int64_t j = grid.Index(r, cc);
        if (comp[j] < 0) comp[j] = next, stack.push_back(j);
      }
    }
    ++next;
  }
  if (num_components) *num_components = next;
  return comp;
}

AnyAngleSearch::AnyAngleSearch(const Grid& grid)
    : grid_(grid),
      dist_(grid.size(), kUnreached),
      parent_(grid.size(), -1),
      closed_(grid.size(), 0) {}

namespace {

float Euclid(const Grid& g, int64_t a, int64_t b) {
  const CellIndex ca = g.FromIndex(a), cb = g.FromIndex(b);
  const float dr = static_cast<float>(ca.row - cb.row), dc = static_cast<float>(ca.col - cb.col);
  return std::sqrt(dr * dr + dc * dc);
}

template <typename F>
void ForEachMove(const Grid& g, CellIndex c, F&& f) {
  ForEachDriveMove(g, c, [&](int64_t n, bool) { f(n); });
}

// Lazy Theta*: the parent of the cell s being settled was assumed visible
// when s was queued; if it is not, s takes its best closed neighbour.
void RepairParent(const Grid& g, int32_t s, CellIndex cs, float unreached, std::vector<float>& dist,
                  std::vector<int32_t>& parent, const std::vector<uint8_t>& closed) {
  const int32_t p = parent[s];
  if (p == s || LineOfSight(g, g.FromIndex(p), cs)) return;
  float best = unreached;
  int32_t best_parent = -1;
  ForEachMove(g, cs, [&](int64_t n) {
    if (!closed[n]) return;
    const float cand = dist[n] + Euclid(g, n, s);
    if (cand < best) best = cand, best_parent = static_cast<int32_t>(n);
  });
  if (best_parent >= 0) dist[s] = best, parent[s] = best_parent;
}

// The any-angle step out of the settled cell s: each open move n is reached
// straight from s's parent. improved(n, cost) runs before n's entries are
// overwritten (it queues n, and may note that n was unreached).
template <typename F>
void RelaxThroughParent(const Grid& g, int32_t s, CellIndex cs, std::vector<float>& dist,
                        std::vector<int32_t>& parent, const std::vector<uint8_t>& closed, F&& improved) {
  const int32_t ps = parent[s];
  ForEachMove(g, cs, [&](int64_t n) {
    if (closed[n]) return;
    const float cand = dist[ps] + Euclid(g, ps, n);
    if (cand < dist[n]) {
      improved(n, cand);
      dist[n] = cand;
      parent[n] = ps;
    }
  });
}

}  // namespace

bool AnyAngleSearch::Run(CellIndex source, const StopToken& stop) {
  std::fill(dist_.begin(), dist_.end(), kUnreached);
  std::fill(parent_.begin(), parent_.end(), -1);
  std::fill(closed_.begin(), closed_.end(), 0);
  touched_.clear();
  all_dirty_ = true;
  if (!grid_.IsFree(source)) return true;
  source_ = grid_.Index(source.row, source.col);
  using Entry = std::pair<float, int32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  dist_[source_] = 0.0f;
  parent_[source_] = static_cast<int32_t>(source_);
  open.push({0.0f, static_cast<int32_t>(source_)});
  int64_t expansions = 0;
  while (!open.empty()) {
    const auto [d, s] = open.top();
    open.pop();
    if (closed_[s] || d > dist_[s]) continue;
    if ((++expansions & 1023) == 0 && stop.ShouldStop()) return false;
    const CellIndex cs = grid_.FromIndex(s);
    RepairParent(grid_, s, cs, kUnreached, dist_, parent_, closed_);
    closed_[s] = 1;
    RelaxThroughParent(grid_, s, cs, dist_, parent_, closed_,
                       [&](int64_t n, float cand) { open.push({cand, static_cast<int32_t>(n)}); });
  }
  return true;
}

void AnyAngleSearch::Reset() {
  if (all_dirty_) {
    std::fill(dist_.begin(), dist_.end(), kUnreached);
    std::fill(parent_.begin(), parent_.end(), -1);
    std::fill(closed_.begin(), closed_.end(), 0);
    all_dirty_ = false;
  } else {
    for (int32_t i : touched_) dist_[i] = kUnreached, parent_[i] = -1, closed_[i] = 0;
  }
  touched_.clear();
}

bool AnyAngleSearch::RunTo(CellIndex source, CellIndex target, const StopToken& stop, int64_t max_expansions,
                           float* bound) {
  Reset();
  if (!grid_.IsFree(source) || !grid_.IsFree(target)) return true;
  source_ = grid_.Index(source.row, source.col);
  const int64_t goal = grid_.Index(target.row, target.col);
  // Ties (frequent in open areas) go to the cell nearer the goal.
  auto h = [&](int64_t i) { return Euclid(grid_, i, goal) * (1.0f + 1e-5f); };
  using Entry = std::pair<float, int32_t>;  // (g + h, cell)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  dist_[source_] = 0.0f;
  parent_[source_] = static_cast<int32_t>(source_);
  touched_.push_back(static_cast<int32_t>(source_));
  open.push({h(source_), static_cast<int32_t>(source_)});
  int64_t expansions = 0;
  while (!open.empty()) {
    const auto [f, s] = open.top();
    open.pop();
    if (closed_[s] || f > dist_[s] + h(s) + 1e-4f) continue;
    if (++expansions > max_expansions) {
      if (bound != nullptr) *bound = f;
      return false;
    }
    if ((expansions & 1023) == 0 && stop.ShouldStop()) return false;
    const CellIndex cs = grid_.FromIndex(s);
    RepairParent(grid_, s, cs, kUnreached, dist_, parent_, closed_);
    closed_[s] = 1;
    if (s == goal) return true;
    RelaxThroughParent(grid_, s, cs, dist_, parent_, closed_, [&](int64_t n, float cand) {
      if (dist_[n] >= kUnreached) touched_.push_back(static_cast<int32_t>(n));
      open.push({cand + h(n), static_cast<int32_t>(n)});
    });
  }
  return true;
}

bool AnyAngleSearch::Explore(CellIndex source, int64_t max_settled, const StopToken& stop,
                             const std::function<bool(int64_t, float)>& settle) {
  Reset();
  if (!grid_.IsFree(source)) return true;
  source_ = grid_.Index(source.row, source.col);
  using Entry = std::pair<float, int32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  dist_[source_] = 0.0f;
  parent_[source_] = static_cast<int32_t>(source_);
  touched_.push_back(static_cast<int32_t>(source_));
  open.push({0.0f, static_cast<int32_t>(source_)});
  int64_t expansions = 0, settled = 0;
  while (!open.empty()) {
    const auto [d, s] = open.top();
    open.pop();
    if (closed_[s] || d > dist_[s]) continue;
    if ((++expansions & 1023) == 0 && stop.ShouldStop()) return false;
    const CellIndex cs = grid_.FromIndex(s);
    RepairParent(grid_, s, cs, kUnreached, dist_, parent_, closed_);
    closed_[s] = 1;
    if (!settle(s, dist_[s]) || ++settled >= max_settled) return true;
    RelaxThroughParent(grid_, s, cs, dist_, parent_, closed_, [&](int64_t n, float cand) {
      if (dist_[n] >= kUnreached) touched_.push_back(static_cast<int32_t>(n));
      open.push({cand, static_cast<int32_t>(n)});
    });
  }
  return true;
}

std::vector<CellIndex> AnyAngleSearch::PathTo(CellIndex target) const {
  std::vector<CellIndex> path;
  if (!grid_.IsFree(target)) return path;
  int64_t v = grid_.Index(target.row, target.col);
  if (dist_[v] >= kUnreached || !closed_[v]) return path;
  while (true) {
    path.push_back(grid_.FromIndex(v));
    if (v == source_) break;
    v = parent_[v];
  }
  std::reverse(path.begin(), path.end());
  return path;
}

bool SegmentTouches(const Grid& frame, Point2 a, Point2 b, const std::function<bool(int, int)>& closed) {
  const double s = frame.cell_size();
  const double ax = (a.x - frame.origin().x) / s, ay = (a.y - frame.origin().y) / s;
  const double bx = (b.x - frame.origin().x) / s, by = (b.y - frame.origin().y) / s;
  int cx = static_cast<int>(std::floor(ax)), cy = static_cast<int>(std::floor(ay));
  const int ex = static_cast<int>(std::floor(bx)), ey = static_cast<int>(std::floor(by));
  if (closed(cy, cx)) return true;
  const double dx = bx - ax, dy = by - ay;
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  double tx = dx != 0 ? ((sx > 0 ? cx + 1 : cx) - ax) / dx : inf;
  double ty = dy != 0 ? ((sy > 0 ? cy + 1 : cy) - ay) / dy : inf;
  const double dtx = dx != 0 ? sx / dx : inf, dty = dy != 0 ? sy / dy : inf;
  for (int guard = std::abs(ex - cx) + std::abs(ey - cy) + 2; guard > 0 && (cx != ex || cy != ey); --guard) {
    if (std::abs(tx - ty) <= 1e-12) {
      if (tx > 1.0) break;
      // Exactly through a grid corner: all four cells around it are touched.
      if (closed(cy, cx + sx) || closed(cy + sy, cx)) return true;
      cx += sx, cy += sy, tx += dtx, ty += dty;
    } else if (tx < ty) {
      if (tx > 1.0) break;
      cx += sx, tx += dtx;
    } else {
      if (ty > 1.0) break;
      cy += sy, ty += dty;
    }
    if (closed(cy, cx)) return true;
  }
  return false;
}

absl::StatusOr<CellIndex> JoinCell(const Grid& grid, const Pose2& p, const char* what) {
  const CellIndex c = grid.CellAt({p.x, p.y});
  if (grid.IsFree(c)) return c;
  // Free neighbours, nearest centre first.
  std::vector<std::pair<double, CellIndex>> candidates;
  // Far outside the grid (CellAt clamps to -2 / n + 1): no free neighbour.
  const bool near_grid = c.row >= -1 && c.col >= -1 && c.row <= grid.rows() && c.col <= grid.cols();
  for (int dr = -1; near_grid && dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      const CellIndex n{c.row + dr, c.col + dc};
      if (!grid.IsFree(n)) continue;
      const Point2 q = grid.CellCenter(n);
      candidates.push_back({(q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y), n});
    }
  }
  if (candidates.empty()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s pose (%.3f, %.3f) is neither in nor next to a reachable free grid cell (cells of "
        "%.3f m; only the largest connected free area is planned)",
        what, p.x, p.y, grid.cell_size()));
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [d2, n] : candidates) {
    // Only the pose's own cell may be blocked on the way.
    const bool clear = !SegmentTouches(grid, {p.x, p.y}, grid.CellCenter(n), [&](int r, int col) {
      return !(r == c.row && col == c.col) && !grid.IsFree(r, col);
    });
    if (clear) return n;
  }
  return candidates.front().second;
}

}  // namespace covplan
