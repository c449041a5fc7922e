#include "planner/tour/grid_paths.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
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

uint8_t DriveMoveMask(const Grid& g, CellIndex c) {
  uint8_t mask = 0;
  for (int k = 0; k < 8; ++k) {
    const int dr = kDriveDr[k], dc = kDriveDc[k];
    bool open;
    if (k < 4) {
      open = g.Passable(c.row, c.col, dr, dc);
    } else {
      open = g.Passable(c.row, c.col, 0, dc) && g.Passable(c.row, c.col + dc, dr, 0) &&
             g.Passable(c.row, c.col, dr, 0) && g.Passable(c.row + dr, c.col, 0, dc) &&
             (g.obstacle_pixels() == nullptr ||
              !g.obstacle_pixels()->DiagonalBlocked(c.row, c.col, dr, dc));
    }
    mask |= static_cast<uint8_t>(open) << k;
  }
  return mask;
}

AnyAngleSearch::AnyAngleSearch(const Grid& grid)
    : grid_(grid),
      dist_(grid.size(), kUnreached),
      parent_(grid.size(), -1),
      closed_(grid.size(), 0),
      moves_(grid.size(), 0) {}

namespace {

// Euclidean distance between cell centres, in cells. The searches compare
// these floats exactly, so every caller uses this one formula.
float Euclid(CellIndex a, CellIndex b) {
  const float dr = static_cast<float>(a.row - b.row), dc = static_cast<float>(a.col - b.col);
  return std::sqrt(dr * dr + dc * dc);
}

// Bit of the 4-neighbour move (dr, dc) in a move mask.
constexpr int StraightBit(int dr, int dc) { return dr > 0 ? 0 : dr < 0 ? 1 : dc > 0 ? 2 : 3; }

}  // namespace

uint16_t AnyAngleSearch::FillMoves(int64_t i, CellIndex c) {
  const ObstaclePixels* px = grid_.obstacle_pixels();
  uint16_t m = static_cast<uint16_t>(DriveMoveMask(grid_, c) | kKnown);
  if (px != nullptr && px->CellDirty(c.row, c.col)) m |= kDirty;
  moves_[i] = m;
  return m;
}

// The walk of LineOfSight, with each cell's passable sides and dirtiness read
// from its move mask (filled once per cell) instead of the grid. Kept apart
// from LineOfSight on purpose: it is the searches' hot loop, and one walk
// shared through accessor lambdas (tried) made the sparse tour search about
// 15 % slower. Tests check the two agree on every pair of cells.
bool AnyAngleSearch::Visible(CellIndex a, CellIndex b) {
  int x = a.col, y = a.row;
  const int dx = b.col - a.col, dy = b.row - a.row;
  const int64_t nx = std::abs(dx), ny = std::abs(dy);
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  if (!grid_.IsFree(y, x)) return false;
  const ObstaclePixels* px = grid_.obstacle_pixels();
  const Point2 pa{a.col + 0.5, a.row + 0.5}, pb{b.col + 0.5, b.row + 0.5};
  const int cols = grid_.cols();
  const uint16_t right = uint16_t{1} << StraightBit(0, sx), up = uint16_t{1} << StraightBit(sy, 0);
  int64_t i = static_cast<int64_t>(y) * cols + x;
  uint16_t m = Moves(i, {y, x});
  auto pixels_clear = [&](uint16_t mask, int r, int c) {
    return !(mask & kDirty) || !px->SegmentBlockedInCell(r, c, pa, pb);
  };
  if (!pixels_clear(m, y, x)) return false;
  for (int64_t ix = 0, iy = 0; ix < nx || iy < ny;) {
    const int64_t decision = (1 + 2 * ix) * ny - (1 + 2 * iy) * nx;
    if (decision == 0) {
      // Exactly through a grid corner: all four cells around it are touched,
      // and no barrier may meet the corner.
      if (!(m & right)) return false;
      const uint16_t mx = Moves(i + sx, {y, x + sx});
      if (!(mx & up) || !(m & up)) return false;
      const uint16_t my = Moves(i + static_cast<int64_t>(sy) * cols, {y + sy, x});
      if (!(my & right)) return false;
      if (!pixels_clear(mx, y, x + sx) || !pixels_clear(my, y + sy, x)) return false;
      x += sx, y += sy, ++ix, ++iy;
      i += sx + static_cast<int64_t>(sy) * cols;
    } else if (decision < 0) {
      if (!(m & right)) return false;
      x += sx, ++ix;
      i += sx;
    } else {
      if (!(m & up)) return false;
      y += sy, ++iy;
      i += static_cast<int64_t>(sy) * cols;
    }
    m = Moves(i, {y, x});
    if (!pixels_clear(m, y, x)) return false;
  }
  return true;
}

// Lazy Theta*: the parent of the cell s being settled was assumed visible
// when s was queued; if it is not, s takes its best closed neighbour.
void AnyAngleSearch::RepairParent(int32_t s, CellIndex cs) {
  const int32_t p = parent_[s];
  if (p == s || Visible(grid_.FromIndex(p), cs)) return;
  float best = kUnreached;
  int32_t best_parent = -1;
  const uint16_t m = Moves(s, cs);
  for (int k = 0; k < 8; ++k) {
    if (!(m >> k & 1)) continue;
    const CellIndex cn{cs.row + kDriveDr[k], cs.col + kDriveDc[k]};
    const int32_t n = static_cast<int32_t>(grid_.Index(cn.row, cn.col));
    if (!closed_[n]) continue;
    const float cand = dist_[n] + Euclid(cn, cs);
    if (cand < best) best = cand, best_parent = n;
  }
  if (best_parent >= 0) dist_[s] = best, parent_[s] = best_parent;
}

// The any-angle step out of the settled cell s: each open move n is reached
// straight from s's parent. improved(n, cell of n, cost) runs before n's
// entries are overwritten (it queues n, and may note that n was unreached).
template <typename F>
void AnyAngleSearch::RelaxThroughParent(int32_t s, CellIndex cs, F&& improved) {
  const int32_t ps = parent_[s];
  const CellIndex cp = grid_.FromIndex(ps);
  const float dp = dist_[ps];
  const uint16_t m = Moves(s, cs);
  for (int k = 0; k < 8; ++k) {
    if (!(m >> k & 1)) continue;
    const CellIndex cn{cs.row + kDriveDr[k], cs.col + kDriveDc[k]};
    const int32_t n = static_cast<int32_t>(grid_.Index(cn.row, cn.col));
    if (closed_[n]) continue;
    const float cand = dp + Euclid(cp, cn);
    if (cand < dist_[n]) {
      improved(n, cn, cand);
      dist_[n] = cand;
      parent_[n] = ps;
    }
  }
}

bool AnyAngleSearch::Run(CellIndex source, const StopToken& stop) {
  std::fill(dist_.begin(), dist_.end(), kUnreached);
  std::fill(parent_.begin(), parent_.end(), -1);
  std::fill(closed_.begin(), closed_.end(), 0);
  touched_.clear();
  all_dirty_ = true;
  resumable_ = false;
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
    RepairParent(s, cs);
    closed_[s] = 1;
    RelaxThroughParent(s, cs, [&](int32_t n, CellIndex, float cand) { open.push({cand, n}); });
  }
  return true;
}

void AnyAngleSearch::Reset() {
  resumable_ = false;
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

bool AnyAngleSearch::RunTo(CellIndex source, CellIndex target, const StopToken& stop,
                           int64_t max_expansions, float* bound) {
  // Ties (frequent in open areas) go to the cell nearer the goal.
  auto h = [&](CellIndex c) { return Euclid(c, target) * (1.0f + 1e-5f); };
  using Entry = std::pair<float, int32_t>;  // (g + h, cell)
  const std::greater<Entry> later;
  const bool resume = resumable_ && grid_.IsFree(source) && grid_.IsFree(target) &&
                      source_ == grid_.Index(source.row, source.col) &&
                      goal_ == grid_.Index(target.row, target.col);
  if (!resume) {
    Reset();
    if (!grid_.IsFree(source) || !grid_.IsFree(target)) return true;
    source_ = grid_.Index(source.row, source.col);
    goal_ = grid_.Index(target.row, target.col);
    dist_[source_] = 0.0f;
    parent_[source_] = static_cast<int32_t>(source_);
    touched_.push_back(static_cast<int32_t>(source_));
    open_.clear();
    open_.push_back({h(source), static_cast<int32_t>(source_)});
    expansions_ = 0;
  }
  resumable_ = false;
  while (!open_.empty()) {
    std::pop_heap(open_.begin(), open_.end(), later);
    const auto [f, s] = open_.back();
    open_.pop_back();
    if (closed_[s]) continue;
    const CellIndex cs = grid_.FromIndex(s);
    if (f > dist_[s] + h(cs) + 1e-4f) continue;
    if (++expansions_ > max_expansions) {
      // Put the entry back uncounted, so that a resumed call expands it.
      open_.push_back({f, s});
      std::push_heap(open_.begin(), open_.end(), later);
      --expansions_;
      resumable_ = true;
      if (bound != nullptr) *bound = f;
      return false;
    }
    if ((expansions_ & 1023) == 0 && stop.ShouldStop()) return false;
    RepairParent(s, cs);
    closed_[s] = 1;
    if (s == goal_) return true;
    RelaxThroughParent(s, cs, [&](int32_t n, CellIndex cn, float cand) {
      if (dist_[n] >= kUnreached) touched_.push_back(n);
      open_.push_back({cand + h(cn), n});
      std::push_heap(open_.begin(), open_.end(), later);
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
    RepairParent(s, cs);
    closed_[s] = 1;
    if (!settle(s, dist_[s]) || ++settled >= max_settled) return true;
    RelaxThroughParent(s, cs, [&](int32_t n, CellIndex, float cand) {
      if (dist_[n] >= kUnreached) touched_.push_back(n);
      open.push({cand, n});
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

bool SegmentTouches(const Grid& frame, Point2 a, Point2 b,
                    const std::function<bool(int, int)>& closed) {
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
  for (int guard = std::abs(ex - cx) + std::abs(ey - cy) + 2; guard > 0 && (cx != ex || cy != ey);
       --guard) {
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
    if (ClearJoin(grid, p, n)) return n;
  }
  return candidates.front().second;
}

bool ClearJoin(const Grid& grid, const Pose2& p, CellIndex cell) {
  const CellIndex own = grid.CellAt({p.x, p.y});
  return !SegmentTouches(grid, {p.x, p.y}, grid.CellCenter(cell), [&](int r, int col) {
    return !(r == own.row && col == own.col) && !grid.IsFree(r, col);
  });
}

}  // namespace covplan
