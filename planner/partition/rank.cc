#include "planner/partition/rank.h"

namespace covplan {

std::vector<Rank> RanksFromOrientation(const Grid& grid, const std::vector<uint8_t>& orientation) {
  std::vector<Rank> ranks;
  auto is = [&](int r, int c, Orientation o) {
    return grid.IsFree(r, c) && orientation[grid.Index(r, c)] == static_cast<uint8_t>(o);
  };
  const auto kH = Orientation::kHorizontal, kV = Orientation::kVertical;
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!is(r, c, kH) || (grid.LeftLinked(r, c) && is(r, c - 1, kH))) continue;
      int e = c;
      while (grid.Passable(r, e, 0, 1) && is(r, e + 1, kH)) ++e;
      ranks.push_back({kH, {r, c}, {r, e}});
    }
  }
  for (int c = 0; c < grid.cols(); ++c) {
    for (int r = 0; r < grid.rows(); ++r) {
      if (!is(r, c, kV) || (grid.BelowLinked(r, c) && is(r - 1, c, kV))) continue;
      int e = r;
      while (grid.Passable(e, c, 1, 0) && is(e + 1, c, kV)) ++e;
      ranks.push_back({kV, {r, c}, {e, c}});
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
        starts += !(grid.LeftLinked(r, c) && orientation[grid.Index(r, c - 1)] == 0);
      } else {
        starts += !(grid.BelowLinked(r, c) && orientation[grid.Index(r - 1, c)] == 1);
      }
    }
  }
  return starts;
}

}  // namespace covplan
