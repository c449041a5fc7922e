#include "planner/grid/grid.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"

namespace covplan {

absl::Status GridOptions::Validate() const {
  if (!std::isfinite(cell_size) || cell_size <= 0.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("tool width must be a positive number of metres, got %g", cell_size));
  }
  if (!std::isfinite(min_free_fraction) || min_free_fraction < 0.0 || min_free_fraction >= 1.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("min_free_fraction must be in [0, 1), got %g", min_free_fraction));
  }
  if (max_cells <= 0) return absl::InvalidArgumentError("max_cells must be positive");
  return absl::OkStatus();
}

Grid::Grid(int rows, int cols, double cell_size, Point2 origin, std::vector<uint8_t> free,
           std::vector<uint8_t> walls, std::shared_ptr<const ObstaclePixels> pixels)
    : rows_(rows),
      cols_(cols),
      cell_size_(cell_size),
      origin_(origin),
      free_(std::move(free)),
      walls_(std::move(walls)),
      pixels_(std::move(pixels)) {}

int64_t Grid::CountBarriers() const {
  int64_t n = 0;
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) {
      n += IsFree(r, c) && IsFree(r, c + 1) && !Passable(r, c, 0, 1);
      n += IsFree(r, c) && IsFree(r + 1, c) && !Passable(r, c, 1, 0);
    }
  }
  return n;
}

Grid Grid::FromAscii(const std::vector<std::string>& rows_top_down, double cell_size) {
  const int rows = static_cast<int>(rows_top_down.size());
  const int cols = rows == 0 ? 0 : static_cast<int>(rows_top_down[0].size());
  std::vector<uint8_t> free(static_cast<size_t>(rows) * cols, 0);
  std::vector<uint8_t> walls(static_cast<size_t>(rows) * cols, 0);
  bool any_wall = false;
  for (int i = 0; i < rows; ++i) {
    const int r = rows - 1 - i;
    for (int c = 0; c < cols && c < static_cast<int>(rows_top_down[i].size()); ++c) {
      const char ch = rows_top_down[i][c];
      free[static_cast<size_t>(r) * cols + c] = ch != '#' ? 1 : 0;
      if (ch == '|') walls[static_cast<size_t>(r) * cols + c] |= kWallRight, any_wall = true;
      if (ch == '_' && r > 0)
        walls[static_cast<size_t>(r - 1) * cols + c] |= kWallUp, any_wall = true;
    }
  }
  if (!any_wall) walls.clear();
  return Grid(rows, cols, cell_size, {0.0, 0.0}, std::move(free), std::move(walls));
}

int64_t Grid::CountFree() const {
  int64_t n = 0;
  for (uint8_t f : free_) n += (f != 0);
  return n;
}

CellIndex Grid::CellAt(Point2 p) const {
  // Clamped to [-2, n + 1]: far-away (or non-finite) points stay out of
  // bounds and at least two cells from the grid, and the int cast is defined.
  auto index = [](double v, int n) {
    if (!(v >= -2.0)) return -2;  // also NaN
    if (v > n + 1.0) return n + 1;
    return static_cast<int>(std::floor(v));
  };
  return {index((p.y - origin_.y) / cell_size_, rows_),
          index((p.x - origin_.x) / cell_size_, cols_)};
}

std::vector<std::string> Grid::ToRowStrings() const {
  std::vector<std::string> out(rows_, std::string(cols_, '0'));
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < cols_; ++c) out[r][c] = IsFree(r, c) ? '1' : '0';
  }
  return out;
}

double SnapToInteger(double x) {
  const double r = std::round(x);
  return std::abs(x - r) < 1e-9 * std::max(1.0, std::abs(x)) ? r : x;
}

namespace {

// Free area (in pixel units) of every grid cell, computed exactly with
// fractional overlap of boundary pixels. Separable: per pixel row, prefix sums
// over columns give the column-weighted sum in O(1).
class FreeAreaIntegrator {
 public:
  explicit FreeAreaIntegrator(const OccupancyMap& map) : map_(map) {
    const int w = map.width();
    prefix_.assign(static_cast<size_t>(map.height()) * (w + 1), 0);
    for (int r = 0; r < map.height(); ++r) {
      int32_t* row = &prefix_[static_cast<size_t>(r) * (w + 1)];
      for (int c = 0; c < w; ++c) row[c + 1] = row[c] + (map.IsFree(r, c) ? 1 : 0);
    }
  }

  // Free pixel area of the rectangle [x0, x1) x [y0, y1) in pixel coordinates.
  double Area(double x0, double x1, double y0, double y1) const {
    const int w = map_.width();
    const int h = map_.height();
    x0 = std::max(0.0, x0);
    y0 = std::max(0.0, y0);
    x1 = std::min<double>(w, x1);
    y1 = std::min<double>(h, y1);
    if (x0 >= x1 || y0 >= y1) return 0.0;
    const int r_begin = static_cast<int>(std::floor(y0));
    const int r_end = static_cast<int>(std::ceil(y1));
    double total = 0.0;
    for (int r = r_begin; r < r_end && r < h; ++r) {
      const double wy = std::min<double>(r + 1, y1) - std::max<double>(r, y0);
      if (wy <= 0.0) continue;
      total += wy * RowSum(r, x0, x1);
    }
    return total;
  }

 private:
  double RowSum(int r, double x0, double x1) const {
    const int w = map_.width();
    const int32_t* row = &prefix_[static_cast<size_t>(r) * (w + 1)];
    const int c0 = static_cast<int>(std::floor(x0));
    const int c1 = static_cast<int>(std::floor(x1));  // column containing x1
    if (c0 == c1) return (x1 - x0) * (row[c0 + 1] - row[c0]);
    double s = (c0 + 1 - x0) * (row[c0 + 1] - row[c0]);    // partial first column
    s += row[c1] - row[c0 + 1];                            // full columns
    if (c1 < w) s += (x1 - c1) * (row[c1 + 1] - row[c1]);  // partial last column
    return s;
  }

  const OccupancyMap& map_;
  std::vector<int32_t> prefix_;
};

// True when any pixel touched by the axis-parallel segment between two pixel
// coordinates (x0, y) .. (x1, y) (horizontal) is not free. A coordinate on a
// pixel boundary touches the pixels on both sides.
bool HorizontalLineBlocked(const OccupancyMap& map, double y, double x0, double x1) {
  const int r_lo = static_cast<int>(std::floor(y - 1e-9)),
            r_hi = static_cast<int>(std::floor(y + 1e-9));
  const int c0 = std::max(0, static_cast<int>(std::floor(x0))),
            c1 = std::min(map.width() - 1, static_cast<int>(std::ceil(x1)) - 1);
  for (int r = std::max(0, r_lo); r <= std::min(map.height() - 1, r_hi); ++r) {
    for (int c = c0; c <= c1; ++c) {
      if (!map.IsFree(r, c)) return true;
    }
  }
  return false;
}

bool VerticalLineBlocked(const OccupancyMap& map, double x, double y0, double y1) {
  const int c_lo = static_cast<int>(std::floor(x - 1e-9)),
            c_hi = static_cast<int>(std::floor(x + 1e-9));
  const int r0 = std::max(0, static_cast<int>(std::floor(y0))),
            r1 = std::min(map.height() - 1, static_cast<int>(std::ceil(y1)) - 1);
  for (int c = std::max(0, c_lo); c <= std::min(map.width() - 1, c_hi); ++c) {
    for (int r = r0; r <= r1; ++r) {
      if (!map.IsFree(r, c)) return true;
    }
  }
  return false;
}

}  // namespace

absl::StatusOr<GridFrame> PlanGridFrame(const OccupancyMap& map, const GridOptions& options) {
  absl::Status valid = options.Validate();
  if (!valid.ok()) return valid;
  const double res = map.resolution();
  if (map.width() <= 0 || map.height() <= 0 || !(res > 0.0) || !std::isfinite(res)) {
    return absl::InvalidArgumentError("map is empty or has no valid resolution");
  }
  const double width_m = map.width() * res;
  const double height_m = map.height() * res;
  if (options.cell_size < res * (1.0 - 1e-9)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "tool width %g m is narrower than one map pixel (%g m): use a coarser map or a wider tool",
        options.cell_size, res));
  }
  if (options.cell_size > width_m || options.cell_size > height_m) {
    return absl::InvalidArgumentError(
        absl::StrFormat("tool width %g m is wider than the map (%g m x %g m)", options.cell_size,
                        width_m, height_m));
  }
  GridFrame f;
  f.px_per_cell = SnapToInteger(options.cell_size / res);
  f.cols = static_cast<int>(std::ceil(SnapToInteger(map.width() / f.px_per_cell)));
  f.rows = static_cast<int>(std::ceil(SnapToInteger(map.height() / f.px_per_cell)));
  f.cell_size = options.cell_size;
  f.origin = map.origin();
  if (static_cast<int64_t>(f.rows) * f.cols > options.max_cells) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "grid of %d x %d cells is above the limit of %d cells: use a wider tool or a smaller map",
        f.rows, f.cols, options.max_cells));
  }
  return f;
}

std::vector<double> CellFreeFractions(const OccupancyMap& map, const GridFrame& f) {
  FreeAreaIntegrator integrator(map);
  const double cell_area = f.px_per_cell * f.px_per_cell;
  std::vector<double> out(static_cast<size_t>(f.rows) * f.cols, 0.0);
  for (int r = 0; r < f.rows; ++r) {
    for (int c = 0; c < f.cols; ++c) {
      const double a = integrator.Area(c * f.px_per_cell, (c + 1) * f.px_per_cell,
                                       r * f.px_per_cell, (r + 1) * f.px_per_cell);
      out[static_cast<size_t>(r) * f.cols + c] = a / cell_area;
    }
  }
  return out;
}

absl::StatusOr<Grid> BuildGridFromFractions(const OccupancyMap& map, const GridOptions& options,
                                            const GridFrame& f,
                                            const std::vector<double>& fractions) {
  const int rows = f.rows, cols = f.cols;
  const double px_per_cell = f.px_per_cell;
  if (fractions.size() != static_cast<size_t>(rows) * cols) {
    return absl::InternalError("cell fractions do not match the grid");
  }
  std::vector<uint8_t> free(static_cast<size_t>(rows) * cols, 0);
  int64_t num_free = 0;
  for (size_t i = 0; i < free.size(); ++i) {
    if (fractions[i] > options.min_free_fraction * (1.0 + 1e-12)) {
      free[i] = 1;
      ++num_free;
    }
  }
  if (num_free == 0) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "map has no free cell at tool width %g m (%d free pixels of %d): check the thresholds, "
        "negate flag and resolution",
        options.cell_size, map.CountFree(), static_cast<int64_t>(map.width()) * map.height()));
  }
  std::vector<uint8_t> walls;
  if (options.thin_wall_barriers) {
    walls.assign(free.size(), 0);
    auto is_free = [&](int r, int c) {
      return r >= 0 && c >= 0 && r < rows && c < cols && free[static_cast<size_t>(r) * cols + c];
    };
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (!is_free(r, c)) continue;
        const double cx = (c + 0.5) * px_per_cell, cy = (r + 0.5) * px_per_cell;
        if (is_free(r, c + 1) && HorizontalLineBlocked(map, cy, cx, cx + px_per_cell)) {
          walls[static_cast<size_t>(r) * cols + c] |= Grid::kWallRight;
        }
        if (is_free(r + 1, c) && VerticalLineBlocked(map, cx, cy, cy + px_per_cell)) {
          walls[static_cast<size_t>(r) * cols + c] |= Grid::kWallUp;
        }
      }
    }
  }
  auto pixels = std::make_shared<const ObstaclePixels>(map, px_per_cell, rows, cols);
  return Grid(rows, cols, options.cell_size, map.origin(), std::move(free), std::move(walls),
              std::move(pixels));
}

absl::StatusOr<Grid> BuildGrid(const OccupancyMap& map, const GridOptions& options) {
  absl::StatusOr<GridFrame> frame = PlanGridFrame(map, options);
  if (!frame.ok()) return frame.status();
  return BuildGridFromFractions(map, options, *frame, CellFreeFractions(map, *frame));
}

Grid Grid::WithFreeFlags(std::vector<uint8_t> free) const {
  return Grid(rows_, cols_, cell_size_, origin_, std::move(free), walls_, pixels_);
}

double CoveredFreeAreaRatio(const OccupancyMap& map, const Grid& grid) {
  const int64_t map_free = map.CountFree();
  if (map_free == 0) return 0.0;
  const double px_per_cell = SnapToInteger(grid.cell_size() / map.resolution());
  FreeAreaIntegrator integrator(map);
  double covered = 0.0;
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!grid.IsFree(r, c)) continue;
      covered += integrator.Area(c * px_per_cell, (c + 1) * px_per_cell, r * px_per_cell,
                                 (r + 1) * px_per_cell);
    }
  }
  return covered / static_cast<double>(map_free);
}

}  // namespace covplan
