#include "planner/boustrophedon/ox_plow.h"

#include <cstdlib>
#include <limits>
#include <utility>

namespace covplan {
namespace {

int Along(SweepAxis axis, CellIndex c) { return axis == SweepAxis::kVertical ? c.row : c.col; }

}  // namespace

std::optional<SweepLines> BuildSweepLines(const Grid& grid, const BcdCell& cell, SweepAxis axis) {
  SweepLines out;
  out.axis = axis;
  if (axis == SweepAxis::kVertical) {
    for (size_t k = 0; k < cell.columns.size(); ++k) {
      std::vector<CellIndex> line;
      for (int r = cell.columns[k].lo; r <= cell.columns[k].hi; ++r) {
        line.push_back({r, cell.first_col + static_cast<int>(k)});
      }
      out.lines.push_back(std::move(line));
    }
    return out;
  }
  int lo = std::numeric_limits<int>::max(), hi = std::numeric_limits<int>::min();
  for (const RowInterval& iv : cell.columns) lo = std::min(lo, iv.lo), hi = std::max(hi, iv.hi);
  for (int r = lo; r <= hi; ++r) {
    std::vector<CellIndex> line;
    for (size_t k = 0; k < cell.columns.size(); ++k) {
      if (!cell.columns[k].Contains(r)) continue;
      const int c = cell.first_col + static_cast<int>(k);
      if (!line.empty() && (line.back().col != c - 1 || !grid.Passable(r, c - 1, 0, 1)))
        return std::nullopt;
      line.push_back({r, c});
    }
    if (line.empty()) return std::nullopt;
    out.lines.push_back(std::move(line));
  }
  // Consecutive rows must be linked somewhere for the move between lines.
  for (size_t k = 0; k + 1 < out.lines.size(); ++k) {
    bool linked = false;
    for (const CellIndex& x : out.lines[k]) {
      const CellIndex& f = out.lines[k + 1].front();
      const CellIndex& b = out.lines[k + 1].back();
      if (x.col >= f.col && x.col <= b.col && grid.Passable(x.row, x.col, 1, 0)) linked = true;
    }
    if (!linked) return std::nullopt;
  }
  return out;
}

SweepLines ChooseSweepLines(const Grid& grid, const BcdCell& cell,
                            std::optional<SweepAxis> forced) {
  std::optional<SweepLines> vertical = BuildSweepLines(grid, cell, SweepAxis::kVertical);
  std::optional<SweepLines> horizontal = BuildSweepLines(grid, cell, SweepAxis::kHorizontal);
  if (!horizontal.has_value()) return *vertical;
  if (forced.has_value()) return *forced == SweepAxis::kHorizontal ? *horizontal : *vertical;
  return horizontal->lines.size() < vertical->lines.size() ? *horizontal : *vertical;
}

PolylineElement OxPlowElement(const Grid& grid, const SweepLines& sl, int tag, bool mirrored) {
  PolylineElement e;
  e.kind = TourElementKind::kCell;
  const CellIndex step = sl.axis == SweepAxis::kVertical ? CellIndex{0, 1} : CellIndex{1, 0};
  auto up = [&](size_t k) { return (k % 2 == 0) != mirrored; };
  auto line_start = [&](size_t k) { return up(k) ? sl.lines[k].front() : sl.lines[k].back(); };
  auto line_end = [&](size_t k) { return up(k) ? sl.lines[k].back() : sl.lines[k].front(); };
  CellIndex at = line_start(0);
  e.first_cell = at;
  e.points.push_back(grid.CellCenter(at));
  auto move = [&](CellIndex to, SegmentKind kind, std::vector<CellIndex> swept) {
    if (kind != SegmentKind::kCoverage && to == at) return;
    e.points.push_back(grid.CellCenter(to));
    e.kinds.push_back(kind);
    e.sweeps.push_back(std::move(swept));
    e.tags.push_back(tag);
    at = to;
  };
  for (size_t k = 0; k < sl.lines.size(); ++k) {
    move(line_end(k), SegmentKind::kCoverage, sl.lines[k]);
    if (k + 1 == sl.lines.size()) break;
    // Cross to the next line where the two are linked, as near as possible
    // to this line's end and the next line's start.
    const CellIndex s = line_start(k + 1);
    const std::vector<CellIndex>& next = sl.lines[k + 1];
    int best = std::numeric_limits<int>::max();
    CellIndex link = at;
    for (const CellIndex& x : sl.lines[k]) {
      const CellIndex y{x.row + step.row, x.col + step.col};
      if (Along(sl.axis, y) < Along(sl.axis, next.front()) ||
          Along(sl.axis, y) > Along(sl.axis, next.back()))
        continue;
      if (!grid.Passable(x.row, x.col, step.row, step.col)) continue;
      const int d = std::abs(Along(sl.axis, at) - Along(sl.axis, x)) +
                    std::abs(Along(sl.axis, x) - Along(sl.axis, s));
      if (d < best) best = d, link = x;
    }
    move(link, SegmentKind::kTransition, {});
    move({link.row + step.row, link.col + step.col}, SegmentKind::kTransition, {});
    move(s, SegmentKind::kTransition, {});
  }
  e.last_cell = at;
  return e;
}

}  // namespace covplan
