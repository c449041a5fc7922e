#include "planner/fleet/geodesic.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace covplan {
namespace {

// The eight steps (rows, columns); bit m of a square's links is step m.
constexpr int kDr[8] = {0, 0, 1, -1, 1, 1, -1, -1};
constexpr int kDc[8] = {1, -1, 0, 0, 1, -1, 1, -1};

int StepOf(int dr, int dc) {
  for (int m = 0; m < 8; ++m) {
    if (kDr[m] == dr && kDc[m] == dc) return m;
  }
  return -1;
}

}  // namespace

GeodesicHops::GeodesicHops(const Grid& drive, const std::vector<Point2>& points,
                           int64_t max_squares) {
  const int64_t cells = std::max<int64_t>(1, drive.size());
  factor_ = 1;
  while (cells > max_squares * factor_ * factor_) ++factor_;
  side_ = drive.cell_size() * factor_;
  const int rows = (drive.rows() + factor_ - 1) / factor_ + 2;
  width_ = (drive.cols() + factor_ - 1) / factor_ + 2;
  links_.assign(static_cast<size_t>(rows) * width_, 0);
  // A point in a blocked cell: a dock, left (or reached) by one step to a
  // neighbouring free cell.
  std::vector<uint8_t> dock(static_cast<size_t>(drive.size()), 0);
  square_.reserve(points.size());
  for (const Point2& p : points) {
    const CellIndex c = drive.CellAt(p);
    if (!drive.InBounds(c.row, c.col)) {
      square_.push_back(-1);
      continue;
    }
    square_.push_back((c.row / factor_ + 1) * width_ + c.col / factor_ + 1);
    if (!drive.IsFree(c)) dock[drive.Index(c.row, c.col)] = 1;
  }
  if (factor_ == 1) {
    LinkCells(drive, dock);
  } else {
    std::vector<uint8_t> open(links_.size(), 0);
    for (int r = 0; r < drive.rows(); ++r) {
      for (int c = 0; c < drive.cols(); ++c) {
        if (drive.IsFree(r, c) || dock[drive.Index(r, c)])
          open[(r / factor_ + 1) * width_ + c / factor_ + 1] = 1;
      }
    }
    LinkBlocks(open);
  }
  open_squares_ = std::count_if(links_.begin(), links_.end(), [](uint8_t l) { return l != 0; });
  for (int32_t s : square_) {
    if (s >= 0 && links_[s] == 0) ++open_squares_;  // an isolated point's square
  }
  dist_.assign(links_.size(), -1);
}

// Around each grid corner, the open cells connected through the passable
// edges that meet there (a dock's cell to all of them) are linked pairwise.
void GeodesicHops::LinkCells(const Grid& drive, const std::vector<uint8_t>& dock) {
  auto open = [&](int r, int c) {
    return drive.IsFree(r, c) || (drive.InBounds(r, c) && dock[drive.Index(r, c)]);
  };
  for (int i = 0; i <= drive.rows(); ++i) {
    for (int j = 0; j <= drive.cols(); ++j) {
      // The cells around corner (i, j): 0 below-left, 1 below-right, 2 above-left, 3 above-right.
      const int cr[4] = {i - 1, i - 1, i, i}, cc[4] = {j - 1, j, j - 1, j};
      std::array<int, 4> comp = {0, 1, 2, 3};
      std::array<bool, 4> is_open, is_dock;
      for (int a = 0; a < 4; ++a) {
        is_open[a] = open(cr[a], cc[a]);
        is_dock[a] = is_open[a] && !drive.IsFree(cr[a], cc[a]);
      }
      auto find = [&](int a) {
        while (comp[a] != a) a = comp[a];
        return a;
      };
      auto join = [&](int a, int b) { comp[find(a)] = find(b); };
      // The four edges meeting the corner: (0,1), (2,3) across, (0,2), (1,3) up.
      const int ea[4] = {0, 2, 0, 1}, eb[4] = {1, 3, 2, 3};
      for (int e = 0; e < 4; ++e) {
        const int a = ea[e], b = eb[e];
        if (!is_open[a] || !is_open[b]) continue;
        if (is_dock[a] || is_dock[b] ||
            drive.Passable(cr[a], cc[a], cr[b] - cr[a], cc[b] - cc[a])) {
          join(a, b);
        }
      }
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) {
          if (is_dock[a] && is_open[b]) join(a, b);
        }
      }
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) {
          if (a == b || !is_open[a] || !is_open[b] || find(a) != find(b)) continue;
          const int m = StepOf(cr[b] - cr[a], cc[b] - cc[a]);
          links_[(cr[a] + 1) * width_ + cc[a] + 1] |= static_cast<uint8_t>(1u << m);
        }
      }
    }
  }
}

// Blocks: every two 8-adjacent open blocks are linked.
void GeodesicHops::LinkBlocks(const std::vector<uint8_t>& open) {
  for (size_t s = 0; s < open.size(); ++s) {
    if (!open[s]) continue;
    for (int m = 0; m < 8; ++m) {
      const int64_t t = static_cast<int64_t>(s) + kDr[m] * width_ + kDc[m];
      if (open[t]) links_[s] |= static_cast<uint8_t>(1u << m);  // the border keeps t inside
    }
  }
}

int64_t GeodesicHops::Search(int from, int max_hops) {
  for (int32_t s : queue_) dist_[s] = -1;
  queue_.clear();
  source_ = from;
  deepest_ = 0;
  const int32_t start = square_[from];
  if (start < 0) return 0;
  int32_t step[8];
  for (int m = 0; m < 8; ++m) step[m] = kDr[m] * width_ + kDc[m];
  dist_[start] = 0;
  queue_.push_back(start);
  for (size_t head = 0; head < queue_.size(); ++head) {
    const int32_t s = queue_[head];
    const int32_t d = dist_[s];
    deepest_ = d;
    if (max_hops >= 0 && d >= max_hops) continue;
    for (uint32_t l = links_[s]; l != 0; l &= l - 1) {
      const int32_t t = s + step[__builtin_ctz(l)];
      if (dist_[t] < 0) {
        dist_[t] = d + 1;
        queue_.push_back(t);
      }
    }
  }
  return static_cast<int64_t>(queue_.size());
}

int GeodesicHops::Hops(int to) const {
  const int32_t t = square_[to];
  if (t < 0 || source_ < 0 || square_[source_] < 0) return 0;
  return dist_[t] >= 0 ? dist_[t] : deepest_ + 1;
}

}  // namespace covplan
