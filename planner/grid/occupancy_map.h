// A metric occupancy map: the input every planner starts from.
//
// Pixels are stored row-major with row 0 at the *smallest y* (the bottom of
// the image as ROS map_server publishes it), column 0 at the smallest x.
// Pixel (r, c) covers the square origin + (c*res, r*res) .. + ((c+1)*res, (r+1)*res).
//
//   OccupancyMap map(width, height, 0.05, {0, 0});
//   map.set(r, c, CellState::kFree);
//
// Thread-safety: immutable after construction is finished; const methods are
// safe to call concurrently.
#ifndef COVPLAN_PLANNER_GRID_OCCUPANCY_MAP_H_
#define COVPLAN_PLANNER_GRID_OCCUPANCY_MAP_H_

#include <cstddef>
#include <cstdint>
#include <vector>

namespace covplan {

enum class CellState : uint8_t { kFree = 0, kOccupied = 1, kUnknown = 2 };

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

class OccupancyMap {
 public:
  OccupancyMap() = default;
  OccupancyMap(int width, int height, double resolution, Point2 origin)
      : width_(width),
        height_(height),
        resolution_(resolution),
        origin_(origin),
        cells_(static_cast<size_t>(width) * height, CellState::kUnknown) {}

  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  Point2 origin() const { return origin_; }

  CellState at(int row, int col) const { return cells_[Index(row, col)]; }
  void set(int row, int col, CellState s) { cells_[Index(row, col)] = s; }
  bool IsFree(int row, int col) const { return at(row, col) == CellState::kFree; }

  int64_t CountFree() const {
    int64_t n = 0;
    for (CellState s : cells_) n += (s == CellState::kFree);
    return n;
  }
  double FreeAreaM2() const { return CountFree() * resolution_ * resolution_; }

 private:
  size_t Index(int row, int col) const { return static_cast<size_t>(row) * width_ + col; }

  int width_ = 0;
  int height_ = 0;
  double resolution_ = 0.0;
  Point2 origin_;
  std::vector<CellState> cells_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_GRID_OCCUPANCY_MAP_H_
