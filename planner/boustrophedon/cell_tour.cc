#include "planner/boustrophedon/cell_tour.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {

absl::StatusOr<CellTourModel> CellTourModel::Create(
    const Grid& drive, std::vector<std::array<PolylineElement, 2>> cells, const Pose2& start,
    std::optional<Pose2> end, std::shared_ptr<const MotionCost> motion, const StopToken& stop,
    int num_threads) {
  if (cells.empty()) return absl::InvalidArgumentError("no cells to tour");
  if (motion == nullptr) return absl::InvalidArgumentError("no motion cost");
  CellTourModel m;
  m.SetPoses(start, end, std::move(motion));
  std::vector<CellIndex> endpoints;
  for (size_t e = 0; e < cells.size(); ++e) {
    for (const PolylineElement& el : cells[e]) {
      if (!IsWellFormed(el)) {
        return absl::InvalidArgumentError(absl::StrFormat("cell %d: malformed ox-plow path", e));
      }
      endpoints.push_back(el.first_cell);
      endpoints.push_back(el.last_cell);
    }
  }
  m.cells_ = std::move(cells);
  m.IndexVertices();
  RETURN_IF_ERROR(m.BuildTable(drive, std::move(endpoints), stop, num_threads));
  std::vector<ElementVariant> variants(m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) {
    const PolylineElement& el = m.Element(v);
    const bool backwards = v % 2 == 1;
    std::vector<Point2> pts = el.points, rev = el.points;
    std::reverse(backwards ? pts.begin() : rev.begin(), backwards ? pts.end() : rev.end());
    // The fallback headings turn with the direction the path is driven in.
    const double axis =
        (el.first_cell.row == el.last_cell.row ? 0.0 : M_PI / 2) + (backwards ? M_PI : 0.0);
    variants[v] = PolylineVariant(pts, rev, axis, axis + M_PI, m.motion());
  }
  m.SetVariants(std::move(variants));
  RETURN_IF_ERROR(m.RoutePoses(stop, "start", "end"));
  return m;
}

absl::Status CellTourModel::Unreachable(int element) const {
  return absl::FailedPreconditionError(
      absl::StrFormat("cell %d cannot be reached from the start", element));
}

void CellTourModel::DriveVariant(int v, TourPathWriter* writer) const {
  DrivePolyline(Element(v), v % 2 == 0, heading_in(v), writer);
}

}  // namespace covplan
