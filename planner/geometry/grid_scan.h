// Internal to planner/geometry: classifies the cells of a square grid against an Area's
// boundary one row at a time, so that only the cells the boundary touches need exact work.
// A cell that no edge touches is wholly inside or wholly outside, which one is decided by the
// parity of edge crossings on the row's centre line.
//
//   GridScanner scan(data, frame);
//   for (int r = scan.row_begin(); r < scan.row_end(); ++r) {
//     scan.LoadRow(r);
//     for (int c = scan.col_begin(); c < scan.col_end(); ++c)
//       if (scan.boundary(c)) ... exact ... else if (scan.CentreInside(c)) ...
//   }
//
// Thread-safety: not thread-safe (holds per-row state); use one scanner per thread.
#ifndef COVPLAN_PLANNER_GEOMETRY_GRID_SCAN_H_
#define COVPLAN_PLANNER_GEOMETRY_GRID_SCAN_H_

#include <cstdint>
#include <vector>

#include "planner/geometry/area_data.h"

namespace covplan::geometry_internal {

struct GridFrame {
  int rows = 0;
  int cols = 0;
  double cell = 1.0;
  Point2 origin;

  double X(int col) const { return origin.x + col * cell; }
  double Y(int row) const { return origin.y + row * cell; }
};

class GridScanner {
 public:
  // `data` must outlive the scanner and be non-empty.
  GridScanner(const AreaData& data, const GridFrame& frame);

  // The cells overlapping the area's bounding box; the others are all outside.
  int row_begin() const { return row_begin_; }
  int row_end() const { return row_end_; }
  int col_begin() const { return col_begin_; }
  int col_end() const { return col_end_; }

  // Prepares row r in [row_begin, row_end); call the queries below for that row only.
  void LoadRow(int r);
  // True when an edge may touch the closed square of (row, c) (conservative by 1e-6 cell).
  bool boundary(int c) const { return boundary_[c - col_begin_] != 0; }
  bool RowHasBoundary() const { return !marked_.empty(); }
  // Parity test at x on the row's centre line; exact unless x is within ~1e-12 of an edge,
  // which cannot happen for the centre of a non-boundary cell.
  bool InsideAtCentreLine(double x) const;
  // The edges (indices into data.edges) that may touch the loaded row's band.
  const std::vector<uint32_t>& row_edges() const { return row_edges_[row_ - row_begin_]; }
  double row_centre_y() const { return centre_y_; }

 private:
  const AreaData& data_;
  GridFrame frame_;
  int row_begin_ = 0, row_end_ = 0, col_begin_ = 0, col_end_ = 0;
  double slack_ = 0.0;                            // widening of each edge's footprint
  std::vector<std::vector<uint32_t>> row_edges_;  // per row in [row_begin, row_end)
  int row_ = 0;
  double centre_y_ = 0.0;
  std::vector<uint8_t> boundary_;  // per col in [col_begin, col_end)
  std::vector<int> marked_;        // cols set in boundary_
  std::vector<double> crossings_;  // sorted x on the centre line
};

}  // namespace covplan::geometry_internal

#endif  // COVPLAN_PLANNER_GEOMETRY_GRID_SCAN_H_
