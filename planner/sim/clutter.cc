#include "planner/sim/clutter.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/grid/grid.h"
#include "planner/tour/grid_paths.h"

namespace covplan {
namespace {

// Pixels (row-major indices) that a rectangle centred at (cx, cy) (pixel
// units) with sides w x h (pixels) rotated by `angle` would newly occupy:
// free pixels whose centre lies inside it.
void RectanglePixels(const OccupancyMap& map, double cx, double cy, double w, double h,
                     double angle, std::vector<int64_t>* out) {
  out->clear();
  const double c = std::cos(angle), s = std::sin(angle);
  const double ex = 0.5 * (std::abs(w * c) + std::abs(h * s));
  const double ey = 0.5 * (std::abs(w * s) + std::abs(h * c));
  const int c0 = std::max(0, static_cast<int>(std::floor(cx - ex)));
  const int c1 = std::min(map.width() - 1, static_cast<int>(std::ceil(cx + ex)));
  const int r0 = std::max(0, static_cast<int>(std::floor(cy - ey)));
  const int r1 = std::min(map.height() - 1, static_cast<int>(std::ceil(cy + ey)));
  for (int r = r0; r <= r1; ++r) {
    for (int col = c0; col <= c1; ++col) {
      const double dx = col + 0.5 - cx, dy = r + 0.5 - cy;
      const double u = dx * c + dy * s, v = -dx * s + dy * c;
      if (std::abs(u) <= 0.5 * w && std::abs(v) <= 0.5 * h && map.IsFree(r, col)) {
        out->push_back(static_cast<int64_t>(r) * map.width() + col);
      }
    }
  }
}

// Free cells of `map`'s grid outside its largest component (-1: no grid).
int64_t CutOffCells(const OccupancyMap& map, const GridOptions& options) {
  absl::StatusOr<Grid> grid = BuildGrid(map, options);
  if (!grid.ok()) return -1;
  int32_t num = 0;
  const std::vector<int32_t> component = FreeComponents(*grid, &num);
  std::vector<int64_t> size(static_cast<size_t>(std::max(num, 0)), 0);
  for (int32_t c : component) {
    if (c >= 0 && c < num) ++size[c];
  }
  int64_t total = 0, largest = 0;
  for (int64_t s : size) total += s, largest = std::max(largest, s);
  return total - largest;
}

}  // namespace

absl::StatusOr<OccupancyMap> AddClutter(const OccupancyMap& map, double percent, uint64_t seed,
                                        const ClutterOptions& options) {
  if (!(percent >= 0.0 && percent <= 50.0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("clutter percent must be in [0, 50], got %g", percent));
  }
  if (!(options.min_side_m > 0.0 && options.max_side_m >= options.min_side_m &&
        std::isfinite(options.max_side_m))) {
    return absl::InvalidArgumentError(
        absl::StrFormat("clutter sides must satisfy 0 < min_side_m <= max_side_m, got %g and %g",
                        options.min_side_m, options.max_side_m));
  }
  GridOptions grid_options;
  grid_options.cell_size = options.keep_connected_cell_m;
  const bool keep_connected = options.keep_connected_cell_m > 0.0;
  if (!(options.keep_connected_cell_m >= 0.0 && std::isfinite(options.keep_connected_cell_m))) {
    return absl::InvalidArgumentError("keep_connected_cell_m must be >= 0");
  }
  std::vector<int64_t> free_pixels;
  for (int r = 0; r < map.height(); ++r) {
    for (int c = 0; c < map.width(); ++c) {
      if (map.IsFree(r, c)) free_pixels.push_back(static_cast<int64_t>(r) * map.width() + c);
    }
  }
  if (free_pixels.empty())
    return absl::InvalidArgumentError("the map has no free pixel to clutter");
  const int64_t free_count = static_cast<int64_t>(free_pixels.size());
  const int64_t target = static_cast<int64_t>(std::llround(percent / 100.0 * free_count));
  const int64_t slack = std::max<int64_t>(1, free_count / 400);  // 0.25 percentage points

  OccupancyMap out = map;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int64_t> pick(0, free_count - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double res = map.resolution();
  double scale = 1.0;  // shrinks the sides when rectangles keep overshooting
  int refused = 0;
  int64_t occupied = 0;
  std::vector<int64_t> pixels;
  const int64_t cut_off = keep_connected ? CutOffCells(map, grid_options) : 0;
  if (cut_off < 0)
    return absl::InvalidArgumentError(
        "keep_connected_cell_m: the map has no grid at that cell size");
  for (int64_t attempt = 0; occupied < target; ++attempt) {
    if (attempt > 50'000'000 || scale * options.max_side_m < res) {
      return absl::FailedPreconditionError(absl::StrFormat(
          "could not place %g %% clutter (%d of %d pixels placed)", percent, occupied, target));
    }
    const int64_t at = free_pixels[pick(rng)];
    const double w =
        scale * (options.min_side_m + unit(rng) * (options.max_side_m - options.min_side_m)) / res;
    const double h =
        scale * (options.min_side_m + unit(rng) * (options.max_side_m - options.min_side_m)) / res;
    const double angle = unit(rng) * M_PI;
    const int row = static_cast<int>(at / map.width()), col = static_cast<int>(at % map.width());
    if (!out.IsFree(row, col)) continue;  // already cluttered
    RectanglePixels(out, col + 0.5, row + 0.5, w, h, angle, &pixels);
    if (occupied + static_cast<int64_t>(pixels.size()) > target + slack) {
      if (++refused >= 200) scale *= 0.5, refused = 0;
      continue;
    }
    auto set_all = [&](CellState state) {
      for (int64_t p : pixels)
        out.set(static_cast<int>(p / map.width()), static_cast<int>(p % map.width()), state);
    };
    set_all(CellState::kOccupied);
    if (keep_connected) {
      const int64_t now = CutOffCells(out, grid_options);
      if (now < 0 || now > cut_off) {  // cuts cells off (or closes the map)
        set_all(CellState::kFree);
        if (++refused >= 200) scale *= 0.5, refused = 0;
        continue;
      }
    }
    refused = 0;
    occupied += static_cast<int64_t>(pixels.size());
  }
  return out;
}

int64_t ClearAround(const OccupancyMap& known, Point2 at, double radius_m, OccupancyMap* truth) {
  const double res = known.resolution();
  const int c0 = static_cast<int>(std::floor((at.x - radius_m - known.origin().x) / res));
  const int c1 = static_cast<int>(std::floor((at.x + radius_m - known.origin().x) / res));
  const int r0 = static_cast<int>(std::floor((at.y - radius_m - known.origin().y) / res));
  const int r1 = static_cast<int>(std::floor((at.y + radius_m - known.origin().y) / res));
  int64_t freed = 0;
  for (int r = std::max(0, r0); r <= std::min(known.height() - 1, r1); ++r) {
    for (int col = std::max(0, c0); col <= std::min(known.width() - 1, c1); ++col) {
      freed += !truth->IsFree(r, col) && known.IsFree(r, col);
      truth->set(r, col, known.at(r, col));
    }
  }
  return freed;
}

}  // namespace covplan
