#include "planner/partition/rank.h"

namespace covplan {

std::vector<Rank> RanksFromOrientation(const Grid& grid, const std::vector<uint8_t>& orientation) {
  std::vector<Rank> ranks;
  auto is = [&](int r, int c, Orientation o) {
    return grid.IsFree(r, c) && orientation[grid.Index(r, c)] == static_cast<uint8_t>(o);
  };
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!is(r, c, Orientation::kHorizontal) || is(r, c - 1, Orientation::kHorizontal)) continue;
      int e = c;
      while (is(r, e + 1, Orientation::kHorizontal)) ++e;
      ranks.push_back({Orientation::kHorizontal, {r, c}, {r, e}});
    }
  }
  for (int c = 0; c < grid.cols(); ++c) {
    for (int r = 0; r < grid.rows(); ++r) {
      if (!is(r, c, Orientation::kVertical) || is(r - 1, c, Orientation::kVertical)) continue;
      int e = r;
      while (is(e + 1, c, Orientation::kVertical)) ++e;
      ranks.push_back({Orientation::kVertical, {r, c}, {e, c}});
    }
  }
  return ranks;
}

int64_t CountRankStarts(const Grid& grid, const std::vector<uint8_t>& orientation) {
  int64_t starts = 0;
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!grid.IsFree(r, c)) continue;
      const uint8_t o = orientation[grid.Index(r, c)];
      if (o == 0) {
        starts += !(grid.IsFree(r, c - 1) && orientation[grid.Index(r, c - 1)] == 0);
      } else {
        starts += !(grid.IsFree(r - 1, c) && orientation[grid.Index(r - 1, c)] == 1);
      }
    }
  }
  return starts;
}

}  // namespace covplan
