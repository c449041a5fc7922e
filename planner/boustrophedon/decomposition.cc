#include "planner/boustrophedon/decomposition.h"

#include <algorithm>

namespace covplan {

int64_t BcdCell::NumCells() const {
  int64_t n = 0;
  for (const RowInterval& r : columns) n += r.hi - r.lo + 1;
  return n;
}

size_t BoustrophedonDecomposition::MemoryBytes() const {
  size_t bytes = sizeof(*this) + cell_of.capacity() * sizeof(int32_t);
  for (const BcdCell& c : cells) bytes += sizeof(c) + c.columns.capacity() * sizeof(RowInterval);
  return bytes;
}

namespace {

// The segments of column c, bottom to top.
std::vector<RowInterval> ColumnSegments(const Grid& grid, int c) {
  std::vector<RowInterval> out;
  for (int r = 0; r < grid.rows(); ++r) {
    if (!grid.IsFree(r, c)) continue;
    if (!out.empty() && out.back().hi == r - 1 && grid.Passable(r - 1, c, 1, 0)) {
      out.back().hi = r;
    } else {
      out.push_back({r, r});
    }
  }
  return out;
}

// True when some row of both intervals links column c to column c + 1.
bool Linked(const Grid& grid, int c, const RowInterval& a, const RowInterval& b) {
  for (int r = std::max(a.lo, b.lo); r <= std::min(a.hi, b.hi); ++r) {
    if (grid.Passable(r, c, 0, 1)) return true;
  }
  return false;
}

}  // namespace

BoustrophedonDecomposition Decompose(const Grid& grid) {
  BoustrophedonDecomposition d;
  d.cell_of.assign(static_cast<size_t>(grid.size()), -1);
  std::vector<RowInterval> prev;
  std::vector<int> prev_cell;
  for (int c = 0; c < grid.cols(); ++c) {
    std::vector<RowInterval> cur = ColumnSegments(grid, c);
    std::vector<int> cur_cell(cur.size(), -1);
    if (c > 0 && !prev.empty() && !cur.empty()) {
      // Degrees of the bipartite link graph between the two slices.
      std::vector<int> right_degree(prev.size(), 0), left_degree(cur.size(), 0),
          left_of(cur.size(), -1);
      for (size_t i = 0; i < prev.size(); ++i) {
        for (size_t j = 0; j < cur.size(); ++j) {
          if (cur[j].lo > prev[i].hi) break;  // segments are sorted bottom to top
          if (!Linked(grid, c - 1, prev[i], cur[j])) continue;
          ++right_degree[i];
          ++left_degree[j];
          left_of[j] = static_cast<int>(i);
        }
      }
      for (size_t j = 0; j < cur.size(); ++j) {
        if (left_degree[j] == 1 && right_degree[left_of[j]] == 1)
          cur_cell[j] = prev_cell[left_of[j]];
      }
    }
    for (size_t j = 0; j < cur.size(); ++j) {
      if (cur_cell[j] < 0) {
        cur_cell[j] = static_cast<int>(d.cells.size());
        d.cells.push_back(BcdCell{c, {}});
      }
      d.cells[cur_cell[j]].columns.push_back(cur[j]);
      for (int r = cur[j].lo; r <= cur[j].hi; ++r) d.cell_of[grid.Index(r, c)] = cur_cell[j];
    }
    prev = std::move(cur);
    prev_cell = std::move(cur_cell);
  }
  return d;
}

}  // namespace covplan
