// CellOverlapFractions and RasterizeArea (declared in area.h).
#include <algorithm>
#include <climits>
#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "planner/geometry/area.h"
#include "planner/geometry/area_data.h"
#include "planner/geometry/edge_queries.h"
#include "planner/geometry/grid_scan.h"

namespace covplan {
namespace {

using geometry_internal::AreaData;
using geometry_internal::ClipBoxM2;
using geometry_internal::ClipToBox;
using geometry_internal::EdgeEntersBox;
using geometry_internal::EdgeNear;
using geometry_internal::GridFrame;
using geometry_internal::GridScanner;
using geometry_internal::RingPieces;
using geometry_internal::ToBoost;
namespace bg = geometry_internal::bg;

bool Finite(Point2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }

// Inside/outside of the cells between boundary cells: one parity test per run.
class RunClassifier {
 public:
  explicit RunClassifier(const GridScanner& scan) : scan_(scan) {}
  void StartRow() { valid_ = false; }
  bool Inside(int c, double centre_x) {
    if (!valid_ || c != next_) inside_ = scan_.InsideAtCentreLine(centre_x);
    valid_ = true;
    next_ = c + 1;
    return inside_;
  }

 private:
  const GridScanner& scan_;
  bool valid_ = false;
  bool inside_ = false;
  int next_ = 0;
};

// Pixel centre in the closed area. Parity is exact away from edges; near one, ask Boost.
bool CentreFree(const AreaData& d, const GridScanner& scan, Point2 p, double tol) {
  if (EdgeNear(d, p, tol)) return bg::covered_by(ToBoost(p), d.shape);
  return scan.InsideAtCentreLine(p.x);
}

// The closed square lies in the closed area.
bool SquareFree(const AreaData& d, const GridScanner& scan, double x0, double y0, double side) {
  return !EdgeEntersBox(d, x0, y0, x0 + side, y0 + side) &&
         scan.InsideAtCentreLine(x0 + 0.5 * side);
}

// Columns per clipped piece of a row.
constexpr int kBlockColumns = 16;

}  // namespace

std::vector<float> CellOverlapFractions(const Area& area, int rows, int cols, double cell,
                                        Point2 origin) {
  if (rows <= 0 || cols <= 0) return {};
  std::vector<float> out(static_cast<size_t>(rows) * cols, 0.0f);
  if (area.empty() || !(cell > 0) || !std::isfinite(cell) || !Finite(origin)) return out;
  const AreaData& d = *area.data_;
  const GridFrame frame{rows, cols, cell, origin};
  GridScanner scan(d, frame);
  RunClassifier runs(scan);
  const double cell_area = cell * cell;
  // Boundary cells are clipped against a piece of the area cut to their row and a block of
  // columns: no clip sees more than the local boundary, and Boost's snapping grid (1e-7 of the
  // extent of each overlay's inputs, see AreaLimits) is that of the block, not of the area.
  // The pieces reach beyond the cells by a margin larger than the snapping of the cuts, so
  // that no snapped cut point lands in a cell.
  const double area_extent =
      std::max(d.max_corner.x - d.min_corner.x, d.max_corner.y - d.min_corner.y);
  const double margin = std::max(0.5 * cell, 1e-5 * area_extent);
  for (int r = scan.row_begin(); r < scan.row_end(); ++r) {
    scan.LoadRow(r);
    runs.StartRow();
    float* row = out.data() + static_cast<size_t>(r) * cols;
    const double y0 = frame.Y(r) - margin, y1 = frame.Y(r + 1) + margin;
    RingPieces strip;
    bool have_strip = false;
    RingPieces piece;
    int piece_end = scan.col_begin();  // columns [.., piece_end) are covered by `piece`
    for (int c = scan.col_begin(); c < scan.col_end(); ++c) {
      const double cx = origin.x + (c + 0.5) * cell;
      if (!scan.boundary(c)) {
        row[c] = runs.Inside(c, cx) ? 1.0f : 0.0f;
        continue;
      }
      // Only the cells the boundary enters get clipped (see ClipBoxM2); cells the boundary
      // just touches are whole.
      const auto inside = [&scan](Point2 p) { return scan.InsideAtCentreLine(p.x); };
      if (!EdgeEntersBox(d, frame.X(c), frame.Y(r), frame.X(c + 1), frame.Y(r + 1))) {
        row[c] = inside(Point2{cx, 0}) ? 1.0f : 0.0f;
        continue;
      }
      if (c >= piece_end) {
        piece_end = std::min(c + kBlockColumns, scan.col_end());
        if (piece_end < scan.col_end() && !have_strip) {
          strip = ClipToBox(d.rings, frame.X(scan.col_begin()) - margin, y0,
                            frame.X(scan.col_end()) + margin, y1);
          have_strip = true;
        }
        piece = ClipToBox(have_strip ? strip : d.rings, frame.X(c) - margin, y0,
                          frame.X(piece_end) + margin, y1);
      }
      const double a =
          ClipBoxM2(d, piece, frame.X(c), frame.Y(r), frame.X(c + 1), frame.Y(r + 1), inside);
      const double fraction = std::clamp(a / cell_area, 0.0, 1.0);
      row[c] = fraction >= 0 ? static_cast<float>(fraction) : 0.0f;  // NaN: cell_area underflow
    }
  }
  return out;
}

absl::StatusOr<OccupancyMap> RasterizeArea(const Area& area, double resolution, RasterRule rule,
                                           int64_t max_pixels) {
  if (area.empty()) return absl::InvalidArgumentError("cannot rasterize an empty area");
  if (!(resolution > 0) || !std::isfinite(resolution)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("raster resolution must be a positive number, got %g", resolution));
  }
  const AreaData& d = *area.data_;
  const double col0 = std::floor(d.min_corner.x / resolution);
  const double row0 = std::floor(d.min_corner.y / resolution);
  const Point2 origin{col0 * resolution, row0 * resolution};
  double width = std::max(1.0, std::ceil(d.max_corner.x / resolution) - col0);
  double height = std::max(1.0, std::ceil(d.max_corner.y / resolution) - row0);
  if (origin.x + width * resolution < d.max_corner.x) width += 1;
  if (origin.y + height * resolution < d.max_corner.y) height += 1;
  if (!(width * height <= static_cast<double>(max_pixels)) || width > INT_MAX || height > INT_MAX) {
    return absl::InvalidArgumentError(
        absl::StrFormat("a %.0f x %.0f image at %g m/px exceeds the limit of %d pixels", width,
                        height, resolution, max_pixels));
  }
  OccupancyMap map(static_cast<int>(width), static_cast<int>(height), resolution, origin);
  const GridFrame frame{map.height(), map.width(), resolution, origin};
  GridScanner scan(d, frame);
  RunClassifier runs(scan);
  const double tol =
      1e-9 * resolution + 1e-12 * std::max({std::abs(d.min_corner.x), std::abs(d.min_corner.y),
                                            std::abs(d.max_corner.x), std::abs(d.max_corner.y)});
  for (int r = 0; r < map.height(); ++r) {
    const bool scanned = r >= scan.row_begin() && r < scan.row_end();
    if (scanned) {
      scan.LoadRow(r);
      runs.StartRow();
    }
    for (int c = 0; c < map.width(); ++c) {
      bool free = false;
      if (scanned && c >= scan.col_begin() && c < scan.col_end()) {
        const double cx = origin.x + (c + 0.5) * resolution;
        if (!scan.boundary(c)) {
          free = runs.Inside(c, cx);
        } else if (rule == RasterRule::kCentre) {
          free = CentreFree(d, scan, Point2{cx, scan.row_centre_y()}, tol);
        } else {
          free = SquareFree(d, scan, frame.X(c), frame.Y(r), resolution);
        }
      }
      map.set(r, c, free ? CellState::kFree : CellState::kOccupied);
    }
  }
  return map;
}

}  // namespace covplan
