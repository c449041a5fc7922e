#include "planner/fleet/detour_turn.h"

#include <algorithm>
#include <cmath>

#include "planner/tour/robot_model.h"

namespace covplan {
namespace {

// Angular pieces each side's crossing points are cut into.
constexpr int kPieces = 64;

// Whether the closed square of some free cell lies within `radius` of p.
bool FreeWithin(const Grid& g, Point2 p, double radius) {
  const double h = g.cell_size();
  const double fx = (p.x - g.origin().x) / h, fy = (p.y - g.origin().y) / h;
  if (!std::isfinite(fx) || !std::isfinite(fy)) return false;
  const double reach = radius / h + 1.0;
  const int c0 = static_cast<int>(std::floor(std::max(fx - reach, -1.0)));
  const int c1 = static_cast<int>(std::floor(std::min(fx + reach, g.cols() + 1.0)));
  const int r0 = static_cast<int>(std::floor(std::max(fy - reach, -1.0)));
  const int r1 = static_cast<int>(std::floor(std::min(fy + reach, g.rows() + 1.0)));
  for (int r = std::max(r0, 0); r <= std::min(r1, g.rows() - 1); ++r) {
    for (int c = std::max(c0, 0); c <= std::min(c1, g.cols() - 1); ++c) {
      if (!g.IsFree(r, c)) continue;
      const double dx =
          std::max({c * h - (p.x - g.origin().x), 0.0, (p.x - g.origin().x) - (c + 1) * h});
      const double dy =
          std::max({r * h - (p.y - g.origin().y), 0.0, (p.y - g.origin().y) - (r + 1) * h});
      if (std::hypot(dx, dy) <= radius) return true;
    }
  }
  return false;
}

// How far from x0 along `dir` the line stays off every free cell: a
// parameter t_end such that no point x0 + t dir with 0 <= t < t_end touches
// a free cell's square; -1 when it never does within the grid (no path
// crosses on that side).
double ClearStretch(const Grid& g, Point2 x0, Point2 dir, double limit) {
  const double step = g.cell_size() / 4.0;
  const double w = g.cols() * g.cell_size(), hgt = g.rows() * g.cell_size();
  // Samples step apart from t = 0: every point within step / 2 of a clear
  // sample is clear, so all of [0, t - step / 2) is when sample t is not.
  for (double t = 0.0;; t += step) {
    const Point2 p{x0.x + t * dir.x, x0.y + t * dir.y};
    if (FreeWithin(g, p, step / 2.0 + 1e-9)) return std::max(0.0, t - step / 2.0);
    if (t >= limit) return t;
    const double px = p.x - g.origin().x, py = p.y - g.origin().y;
    if (px < -g.cell_size() || py < -g.cell_size() || px > w + g.cell_size() ||
        py > hgt + g.cell_size())
      return -1.0;
  }
}

// The least of the turning bound g(p) (detour_turn.h) over the crossing
// points p = x0 + s t n, t >= t_end: alpha = dir(a, p) = d + s atan(t / l1),
// beta = dir(p, b) = d - s atan(t / l2), sampled on kPieces angular pieces,
// each piece bounded below by its better end less twice the change of alpha
// and beta across it (g is 2-Lipschitz in each).
double SideBound(double d, double s, double l1, double l2, double t_end, double ha, double hb) {
  auto f = [&](double ta, double tb) {
    const double alpha = d + s * ta, beta = d - s * tb;
    const double in = HeadingChange(ha, alpha), out = HeadingChange(beta, hb);
    return std::min({in + HeadingChange(alpha, beta) + out,
                     in + 2.0 * M_PI - HeadingChange(alpha, hb),
                     2.0 * M_PI - HeadingChange(ha, beta) + out, 2.0 * M_PI});
  };
  const double ta0 = std::atan(t_end / l1);
  double best = 2.0 * M_PI;
  double prev_a = ta0, prev_b = std::atan(t_end / l2), prev_f = f(prev_a, prev_b);
  for (int i = 1; i <= kPieces; ++i) {
    const double ta = ta0 + (M_PI / 2.0 - ta0) * i / kPieces;
    const double tb = i == kPieces ? M_PI / 2.0 : std::atan(l1 * std::tan(ta) / l2);
    const double value = f(ta, tb);
    const double margin = 2.0 * (ta - prev_a) + 2.0 * (tb - prev_b);
    best = std::min(best, std::max(prev_f, value) - margin);
    prev_a = ta, prev_b = tb, prev_f = value;
  }
  return std::max(0.0, best);
}

// An axis-parallel move between cells of one column (or one row) crosses
// the grid line between two of them through an edge that is not passable
// (a barrier or a blocked cell): the path crosses that line outside the run
// of impassable edges around it, at the run's end corners or beyond (a
// corner inside the run has no open L-route across the line). Calls
// `side(l1, t_pos, t_neg)` per such edge: l1 the distance from a to the
// line, t_pos and t_neg the clear stretch towards +n and -n (-1: none).
template <typename Side>
void ForEachWallCrossing(const Grid& g, Point2 a, Point2 b, Point2 n, Side side) {
  const double h = g.cell_size();
  const CellIndex ca = g.CellAt(a), cb = g.CellAt(b);
  const bool vertical = std::abs(a.x - b.x) <= 1e-9 && ca.col == cb.col;
  const bool horizontal = std::abs(a.y - b.y) <= 1e-9 && ca.row == cb.row;
  if (vertical == horizontal) return;
  const int from = vertical ? ca.row : ca.col, to = vertical ? cb.row : cb.col;
  const int lo = std::min(from, to), hi = std::max(from, to);
  // Edge across the line after index i, at index j along the line.
  auto blocking = [&](int i, int j) {
    return vertical ? !g.Passable(i, j, 1, 0) : !g.Passable(j, i, 0, 1);
  };
  const int along = vertical ? ca.col : ca.row, count = vertical ? g.cols() : g.rows();
  const double pos = vertical ? a.x - g.origin().x : a.y - g.origin().y;
  const double n_along = vertical ? n.x : n.y;
  for (int i = lo; i < hi; ++i) {
    if (!blocking(i, along)) continue;
    int first = along, last = along;
    while (first > 0 && blocking(i, first - 1)) --first;
    while (last + 1 < count && blocking(i, last + 1)) ++last;
    // A run reaching the grid's border leaves no way round on that side (no
    // cells beyond it for an L-route): -1.
    const double to_low = first == 0 ? -1.0 : pos - first * h;
    const double to_high = last + 1 == count ? -1.0 : (last + 1) * h - pos;
    const double line = (vertical ? g.origin().y : g.origin().x) + (i + 1) * h;
    const double l1 = std::abs(line - (vertical ? a.y : a.x));
    side(l1, n_along > 0 ? to_high : to_low, n_along > 0 ? to_low : to_high);
  }
}

}  // namespace

double DetourTurnBound(const Grid& drive, Point2 a, double ha, Point2 b, double hb,
                       double max_length) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  if (!(len > 1e-9) || len > max_length) return 0.0;
  if (!drive.IsFree(drive.CellAt(a)) || !drive.IsFree(drive.CellAt(b))) return 0.0;
  const Point2 u{(b.x - a.x) / len, (b.y - a.y) / len}, n{-u.y, u.x};
  const double d = std::atan2(u.y, u.x);
  const double step = drive.cell_size() / 8.0;
  double bound = 0.0;
  bool in_run = false;
  for (double l1 = step; l1 < len - step / 2.0; l1 += step) {
    const Point2 x0{a.x + l1 * u.x, a.y + l1 * u.y};
    // x0 inside blocked cells (or off the grid), off every free square.
    const bool blocked = !FreeWithin(drive, x0, 1e-9);
    if (!blocked || in_run) {
      in_run = blocked;
      continue;
    }
    in_run = true;                  // the first sample of each blocked run
    double side_best = 2.0 * M_PI;  // no crossing on either side: no path
    for (double s : {1.0, -1.0}) {
      const double t_end = ClearStretch(drive, x0, {s * n.x, s * n.y}, 4.0 * len);
      if (t_end < 0.0) continue;  // no free cell on this side: no crossing
      side_best = std::min(side_best, SideBound(d, s, l1, len - l1, t_end, ha, hb));
    }
    bound = std::max(bound, side_best);
  }
  ForEachWallCrossing(drive, a, b, n, [&](double l1, double t_pos, double t_neg) {
    if (l1 <= 0.0 || l1 >= len) return;
    double side_best = 2.0 * M_PI;
    if (t_pos >= 0.0) side_best = SideBound(d, 1.0, l1, len - l1, t_pos, ha, hb);
    if (t_neg >= 0.0)
      side_best = std::min(side_best, SideBound(d, -1.0, l1, len - l1, t_neg, ha, hb));
    bound = std::max(bound, side_best);
  });
  return std::min(2.0 * M_PI, bound);
}

}  // namespace covplan
