// The grid of tool-width cells ("IOP", thesis §3.6.1) every planner works on.
//
// Square cells of side `cell_size` aligned with the map frame. A cell is free
// when more than `min_free_fraction` (default 50 %) of its area is free map
// area. Row 0 is the smallest y, column 0 the smallest x; cell (r, c) is the
// square origin + (c*s, r*s) .. origin + ((c+1)*s, (r+1)*s). The grid origin
// equals the map origin.
//
// Walls thinner than half a cell do not block a cell, so the grid also keeps
// *barriers* between 4-adjacent free cells: the straight line between their
// centres crosses a non-free map pixel. Planners move between neighbours only
// through Passable() links, so no rank or transition crosses a thin wall.
//
//   GridOptions opt; opt.cell_size = 0.8;
//   absl::StatusOr<Grid> grid = BuildGrid(map, opt);
//
// Thread-safety: immutable after construction; const methods are thread-safe.
#ifndef COVPLAN_PLANNER_GRID_GRID_H_
#define COVPLAN_PLANNER_GRID_GRID_H_

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/grid/obstacle_pixels.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

struct CellIndex {
  int row = 0;
  int col = 0;
  friend bool operator==(CellIndex a, CellIndex b) { return a.row == b.row && a.col == b.col; }
  friend bool operator!=(CellIndex a, CellIndex b) { return !(a == b); }
};

struct GridOptions {
  double cell_size = 0.8;          // metres: the tool width
  double min_free_fraction = 0.5;  // a cell is free when free share > this
  bool thin_wall_barriers = true;  // keep barriers between cells split by a thin wall
  int64_t max_cells = 20'000'000;  // reject grids larger than this

  absl::Status Validate() const;
};

class Grid {
 public:
  Grid() = default;
  // Barrier bits per cell (see Passable).
  static constexpr uint8_t kWallRight = 1;  // between (r, c) and (r, c + 1)
  static constexpr uint8_t kWallUp = 2;     // between (r, c) and (r + 1, c)

  // Builds a grid directly from free flags (row-major, row 0 = smallest y)
  // and optional barrier bits (empty = no barriers).
  // `pixels` (optional) are the map's non-free pixels for segment checks.
  Grid(int rows, int cols, double cell_size, Point2 origin, std::vector<uint8_t> free,
       std::vector<uint8_t> walls = {}, std::shared_ptr<const ObstaclePixels> pixels = nullptr);

  // Parses ASCII art for tests: one string per row, *first string is the top
  // row* (largest y) so the picture reads naturally; '.' free, '#' blocked,
  // '|' a free cell with a barrier on its right side, '_' a free cell with a
  // barrier below it.
  static Grid FromAscii(const std::vector<std::string>& rows_top_down, double cell_size = 1.0);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int64_t size() const { return static_cast<int64_t>(rows_) * cols_; }
  double cell_size() const { return cell_size_; }
  Point2 origin() const { return origin_; }

  bool InBounds(int r, int c) const { return r >= 0 && c >= 0 && r < rows_ && c < cols_; }
  bool IsFree(int r, int c) const { return InBounds(r, c) && free_[Index(r, c)] != 0; }
  bool IsFree(CellIndex c) const { return IsFree(c.row, c.col); }
  int64_t Index(int r, int c) const { return static_cast<int64_t>(r) * cols_ + c; }
  CellIndex FromIndex(int64_t i) const {
    return {static_cast<int>(i / cols_), static_cast<int>(i % cols_)};
  }
  int64_t CountFree() const;
  const std::vector<uint8_t>& free_flags() const { return free_; }
  const std::vector<uint8_t>& walls() const { return walls_; }

  // True when (r, c) and (r + dr, c + dc) are 4-adjacent free cells with no
  // barrier between them.
  bool Passable(int r, int c, int dr, int dc) const {
    const int r2 = r + dr, c2 = c + dc;
    if (!IsFree(r, c) || !IsFree(r2, c2)) return false;
    if (walls_.empty()) return true;
    if (dr == 0) return !(walls_[Index(r, std::min(c, c2))] & kWallRight);
    return !(walls_[Index(std::min(r, r2), c)] & kWallUp);
  }
  // The free neighbour a rank may continue into / a robot may step to.
  bool LeftLinked(int r, int c) const { return Passable(r, c, 0, -1); }
  bool BelowLinked(int r, int c) const { return Passable(r, c, -1, 0); }
  int64_t CountBarriers() const;

  // Centre of a cell in the map frame.
  Point2 CellCenter(int r, int c) const {
    return {origin_.x + (c + 0.5) * cell_size_, origin_.y + (r + 0.5) * cell_size_};
  }
  Point2 CellCenter(CellIndex c) const { return CellCenter(c.row, c.col); }
  // Cell containing a map-frame point (may be out of bounds; points more
  // than a cell outside map to row/col -2 or rows/cols + 1).
  CellIndex CellAt(Point2 p) const;

  // One string per row (row 0 first) of '1' free / '0' blocked.
  std::vector<std::string> ToRowStrings() const;

  // The map's non-free pixels (null for grids not built from a map): straight
  // moves are checked against them as well as against cells and barriers.
  const ObstaclePixels* obstacle_pixels() const { return pixels_.get(); }
  const std::shared_ptr<const ObstaclePixels>& shared_obstacle_pixels() const { return pixels_; }

  // The same grid (barriers, obstacle pixels) with other free flags, e.g.
  // with no-go zones closed or only one component kept. `free` must have
  // size() entries and may only clear cells.
  Grid WithFreeFlags(std::vector<uint8_t> free) const;

  size_t MemoryBytes() const {
    return sizeof(*this) + free_.capacity() + walls_.capacity() +
           (pixels_ ? pixels_->MemoryBytes() : 0);
  }

 private:
  int rows_ = 0;
  int cols_ = 0;
  double cell_size_ = 1.0;
  Point2 origin_;
  std::vector<uint8_t> free_;
  std::vector<uint8_t> walls_;  // empty, or kWall* bits per cell
  std::shared_ptr<const ObstaclePixels> pixels_;
};

// How a map is cut into cells: validated cell size, pixels per cell, shape.
struct GridFrame {
  int rows = 0;
  int cols = 0;
  double cell_size = 0.0;
  double px_per_cell = 1.0;
  Point2 origin;
};
// InvalidArgument when the cell is smaller than a map pixel, larger than the
// map, or the grid exceeds max_cells.
absl::StatusOr<GridFrame> PlanGridFrame(const OccupancyMap& map, const GridOptions& options);
// x rounded to the nearest integer when it is within floating-point noise
// of it, else x: the frame's pixels per cell (0.8 m / 0.05 m is 16).
double SnapToInteger(double x);
// Exact free share (0..1) of every cell of `frame` over `map`, row-major.
std::vector<double> CellFreeFractions(const OccupancyMap& map, const GridFrame& frame);
// The grid whose cells are free when fractions[i] > options.min_free_fraction;
// barriers and obstacle pixels come from `map` (a polygon map passes its exact
// polygon fractions and a conservative rasterisation). InvalidArgument when no
// cell is free.
absl::StatusOr<Grid> BuildGridFromFractions(const OccupancyMap& map, const GridOptions& options,
                                            const GridFrame& frame,
                                            const std::vector<double>& fractions);

// Builds the tool-width grid over `map`. InvalidArgument when the cell is
// smaller than a map pixel, larger than the map, the grid exceeds max_cells,
// or no cell is free.
absl::StatusOr<Grid> BuildGrid(const OccupancyMap& map, const GridOptions& options);

// Share of the map's free area covered by free grid cells (the area the tool
// sweeps when every free cell is covered). 0 when the map has no free area.
double CoveredFreeAreaRatio(const OccupancyMap& map, const Grid& grid);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_GRID_GRID_H_
