#include "planner/plan/floor_measure.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "planner/grid/obstacle_pixels.h"

namespace covplan {
namespace {

// Pixel centres of `reach`'s frame within `radius` pixels of a point
// sampled every half pixel along the path, marked in `out`.
void StampPath(const FloorReach& reach, const std::vector<Waypoint>& path, double radius,
               std::vector<uint8_t>* out) {
  const int64_t w = reach.width, h = reach.height;
  auto stamp = [&](double sx, double sy) {
    const int64_t j0 = std::max<int64_t>(0, static_cast<int64_t>(std::ceil(sy - radius - 0.5)));
    const int64_t j1 =
        std::min<int64_t>(h - 1, static_cast<int64_t>(std::floor(sy + radius - 0.5)));
    for (int64_t j = j0; j <= j1; ++j) {
      const double dy = static_cast<double>(j) + 0.5 - sy;
      const double half2 = radius * radius - dy * dy;
      if (half2 < 0.0) continue;
      const double half = std::sqrt(half2);
      const int64_t i0 = std::max<int64_t>(0, static_cast<int64_t>(std::ceil(sx - half - 0.5)));
      const int64_t i1 =
          std::min<int64_t>(w - 1, static_cast<int64_t>(std::floor(sx + half - 0.5)));
      if (i0 <= i1) std::fill(out->begin() + j * w + i0, out->begin() + j * w + i1 + 1, 1);
    }
  };
  auto px = [&](const Waypoint& p) {
    return Point2{(p.x - reach.origin.x) / reach.pixel_m, (p.y - reach.origin.y) / reach.pixel_m};
  };
  // Only what lies within the radius of the frame can stamp: a segment is
  // clipped to that box first (Liang-Barsky), so that far or non-finite
  // coordinates never reach the integer casts.
  const double lo_x = -radius - 1.0, hi_x = static_cast<double>(w) + radius + 1.0;
  const double lo_y = -radius - 1.0, hi_y = static_cast<double>(h) + radius + 1.0;
  auto clip = [&](Point2* a, Point2* b) {
    if (!std::isfinite(a->x) || !std::isfinite(a->y) || !std::isfinite(b->x) ||
        !std::isfinite(b->y)) {
      return false;
    }
    const double dx = b->x - a->x, dy = b->y - a->y;
    double t0 = 0.0, t1 = 1.0;
    for (auto [p, q] : {std::pair{-dx, a->x - lo_x}, std::pair{dx, hi_x - a->x},
                        std::pair{-dy, a->y - lo_y}, std::pair{dy, hi_y - a->y}}) {
      if (p == 0.0) {
        if (q < 0.0) return false;
        continue;
      }
      const double r = q / p;
      if (p < 0.0) {
        if (r > t1) return false;
        t0 = std::max(t0, r);
      } else {
        if (r < t0) return false;
        t1 = std::min(t1, r);
      }
    }
    *b = Point2{a->x + t1 * dx, a->y + t1 * dy};
    *a = Point2{a->x + t0 * dx, a->y + t0 * dy};
    return true;
  };
  if (path.size() == 1) {
    Point2 a = px(path[0]), b = a;
    if (clip(&a, &b)) stamp(a.x, a.y);
  }
  for (size_t k = 1; k < path.size(); ++k) {
    Point2 a = px(path[k - 1]), b = px(path[k]);
    if (!clip(&a, &b)) continue;
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int64_t steps = 1 + static_cast<int64_t>(std::ceil(len / 0.5));
    for (int64_t s = 0; s <= steps; ++s) {
      const double t = static_cast<double>(s) / static_cast<double>(steps);
      stamp(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
    }
  }
}

// Per pixel of the frame: 1 where more than `threshold` of it lies in `area`.
std::vector<uint8_t> PixelsInside(const Area& area, const FloorReach& r, double threshold) {
  const std::vector<float> share = CellOverlapFractions(
      area, static_cast<int>(r.height), static_cast<int>(r.width), r.pixel_m, r.origin);
  std::vector<uint8_t> out(share.size(), 0);
  for (size_t i = 0; i < share.size(); ++i) out[i] = share[i] > threshold;
  return out;
}

}  // namespace

std::vector<uint8_t> NearSites(const std::vector<uint8_t>& site, int64_t width, int64_t height,
                               double radius2) {
  std::vector<uint8_t> out(site.size(), 0);
  if (width <= 0 || height <= 0 || !(radius2 >= 0.0) ||
      site.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    return out;
  }
  // Down each column, the distance to the nearest site in it: two sweeps
  // over the rows (row-major, so the memory is read in order).
  constexpr int32_t kNone = 1 << 20;
  std::vector<int32_t> g(site.size());
  for (int64_t i = 0; i < width; ++i) g[i] = site[i] ? 0 : kNone;
  for (int64_t j = 1; j < height; ++j) {
    const int32_t* up = g.data() + (j - 1) * width;
    int32_t* row = g.data() + j * width;
    const uint8_t* s = site.data() + j * width;
    for (int64_t i = 0; i < width; ++i) row[i] = s[i] ? 0 : std::min(kNone, up[i] + 1);
  }
  for (int64_t j = height - 2; j >= 0; --j) {
    const int32_t* down = g.data() + (j + 1) * width;
    int32_t* row = g.data() + j * width;
    for (int64_t i = 0; i < width; ++i) row[i] = std::min(row[i], down[i] + 1);
  }
  // Along each row, the squared distance to the nearest site is the lower
  // envelope of the parabolas (x - q)^2 + g_q^2 over the columns q that have
  // a site (Felzenszwalb and Huttenlocher's distance transform), O(width).
  // The envelope's breakpoints are doubles; the distance at each pixel is
  // then taken exactly in integers from the parabola that owns it (where two
  // parabolas are within rounding of each other they are equal there).
  std::vector<int64_t> v(static_cast<size_t>(width));
  std::vector<double> z(static_cast<size_t>(width) + 1);
  for (int64_t j = 0; j < height; ++j) {
    const int32_t* row = g.data() + j * width;
    auto f = [row](int64_t q) {
      return static_cast<double>(row[q]) * row[q] + static_cast<double>(q) * q;
    };
    int64_t k = -1;
    for (int64_t q = 0; q < width; ++q) {
      if (row[q] >= kNone) continue;
      double at = -std::numeric_limits<double>::infinity();
      while (k >= 0) {
        at = (f(q) - f(v[k])) / (2.0 * static_cast<double>(q - v[k]));
        if (at > z[k]) break;
        --k;
      }
      ++k;
      v[k] = q;
      z[k] = k == 0 ? -std::numeric_limits<double>::infinity() : at;
      z[k + 1] = std::numeric_limits<double>::infinity();
    }
    uint8_t* o = out.data() + j * width;
    if (k < 0) continue;  // no site in this row's reach: all 0
    int64_t owner = 0;
    for (int64_t i = 0; i < width; ++i) {
      while (z[owner + 1] < static_cast<double>(i)) ++owner;
      const int64_t dx = i - v[owner], gy = row[v[owner]];
      o[i] = static_cast<double>(dx * dx + gy * gy) <= radius2;
    }
  }
  return out;
}

namespace {

// The reach over a width x height image of pixels where blocked(col, row)
// tells the non-free ones, `ppc` pixels to the drive grid's cell side.
template <typename Blocked>
FloorReach Reach(int64_t width, int64_t height, double ppc, const Blocked& blocked,
                 const Grid& drive, const Area* no_go, const Area* regions) {
  FloorReach r;
  if (width <= 0 || height <= 0 || !(ppc > 0.0)) return r;
  // One blocked pixel around the map: off the map is not free.
  const int64_t w = width + 2, h = height + 2;
  r.pixel_m = drive.cell_size() / ppc;
  r.width = width;
  r.height = height;
  r.origin = drive.origin();
  r.tool_radius_px = 0.5 * ppc;
  std::vector<uint8_t> closed(static_cast<size_t>(w * h), 1);
  const std::vector<uint8_t> zone =
      no_go != nullptr && !no_go->empty() ? PixelsInside(*no_go, r, 1e-6) : std::vector<uint8_t>{};
  for (int64_t j = 0; j < r.height; ++j) {
    for (int64_t i = 0; i < r.width; ++i) {
      closed[(j + 1) * w + i + 1] = blocked(i, j) || (!zone.empty() && zone[j * r.width + i]);
    }
  }
  // Tool centres: pixel centres at least radius + half a pixel from the
  // centre of every closed pixel, flooded from those in the drive grid's
  // free cells.
  // A centre fits where no closed pixel's centre lies nearer than
  // radius + 1/2 (squared distances are integers: nearer means at most the
  // largest integer below the square).
  const double fit2 = (r.tool_radius_px + 0.5) * (r.tool_radius_px + 0.5);
  std::vector<uint8_t> fits = NearSites(closed, w, h, std::ceil(fit2 - 1e-9) - 1.0);
  for (uint8_t& f : fits) f = !f;
  std::vector<uint8_t> centre(closed.size(), 0);
  std::vector<int64_t> queue;  // a stack: the order of the flood does not matter
  for (int64_t j = 1; j + 1 < h; ++j) {
    for (int64_t i = 1; i + 1 < w; ++i) {
      const int64_t p = j * w + i;
      if (!fits[p]) continue;
      const int row = static_cast<int>(std::floor((static_cast<double>(j - 1) + 0.5) / ppc));
      const int col = static_cast<int>(std::floor((static_cast<double>(i - 1) + 0.5) / ppc));
      if (!drive.InBounds(row, col) || !drive.IsFree(CellIndex{row, col})) continue;
      centre[p] = 1;
      queue.push_back(p);
    }
  }
  const int64_t step[4] = {1, -1, w, -w};
  while (!queue.empty()) {
    const int64_t p = queue.back();
    queue.pop_back();
    for (int64_t s : step) {
      const int64_t q = p + s;
      if (centre[q] || !fits[q]) continue;
      centre[q] = 1;
      queue.push_back(q);
    }
  }
  // Touched by a disc at some centre.
  const std::vector<uint8_t> touched =
      NearSites(centre, w, h, r.tool_radius_px * r.tool_radius_px + 1e-9);
  const std::vector<uint8_t> target = regions != nullptr && !regions->empty()
                                          ? PixelsInside(*regions, r, 0.5)
                                          : std::vector<uint8_t>{};
  r.reachable.assign(static_cast<size_t>(r.width * r.height), 0);
  for (int64_t j = 0; j < r.height; ++j) {
    for (int64_t i = 0; i < r.width; ++i) {
      const int64_t p = (j + 1) * w + i + 1;
      const bool in = touched[p] && !closed[p] && (target.empty() || target[j * r.width + i]);
      r.reachable[j * r.width + i] = in;
      r.reachable_px += in;
    }
  }
  return r;
}

}  // namespace

FloorReach ComputeFloorReach(const Grid& drive, const Area* no_go, const Area* regions) {
  const ObstaclePixels* pixels = drive.obstacle_pixels();
  if (pixels == nullptr) return FloorReach{};
  return Reach(
      pixels->width(), pixels->height(), pixels->px_per_cell(),
      [pixels](int64_t i, int64_t j) { return pixels->Blocked(i, j); }, drive, no_go, regions);
}

FloorReach ComputeFloorReach(const OccupancyMap& map, const Grid& drive, const Area* no_go,
                             const Area* regions) {
  return Reach(
      map.width(), map.height(), SnapToInteger(drive.cell_size() / map.resolution()),
      [&map](int64_t i, int64_t j) {
        return !map.IsFree(static_cast<int>(j), static_cast<int>(i));
      },
      drive, no_go, regions);
}

FloorMeasure MeasureFloor(const FloorReach& reach, const std::vector<Waypoint>& path,
                          bool keep_missed) {
  return MeasureFloor(reach, std::vector<const std::vector<Waypoint>*>{&path}, keep_missed);
}

FloorMeasure MeasureFloor(const FloorReach& reach,
                          const std::vector<const std::vector<Waypoint>*>& paths,
                          bool keep_missed) {
  FloorMeasure m;
  if (reach.width <= 0 || reach.height <= 0) return m;
  std::vector<uint8_t> swept(reach.reachable.size(), 0);
  for (const std::vector<Waypoint>* path : paths) {
    if (path != nullptr) StampPath(reach, *path, reach.tool_radius_px, &swept);
  }
  int64_t hit = 0;
  for (size_t p = 0; p < swept.size(); ++p) hit += swept[p] && reach.reachable[p];
  const double px_m2 = reach.pixel_m * reach.pixel_m;
  m.reachable_area_m2 = static_cast<double>(reach.reachable_px) * px_m2;
  m.swept_reachable_m2 = static_cast<double>(hit) * px_m2;
  m.missed_reachable_m2 = static_cast<double>(reach.reachable_px - hit) * px_m2;
  m.swept_reachable_ratio = reach.reachable_px > 0
                                ? static_cast<double>(hit) / static_cast<double>(reach.reachable_px)
                                : 0.0;
  if (keep_missed) {
    m.missed.assign(swept.size(), 0);
    for (size_t p = 0; p < swept.size(); ++p) m.missed[p] = reach.reachable[p] && !swept[p];
  }
  return m;
}

}  // namespace covplan
