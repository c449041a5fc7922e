#include "planner/tour/polyline_tour.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

// Heading of the first non-degenerate segment of `pts`, else `fallback`.
double FirstHeading(const std::vector<Point2>& pts, double fallback) {
  for (size_t i = 1; i < pts.size(); ++i) {
    const double dx = pts[i].x - pts[i - 1].x, dy = pts[i].y - pts[i - 1].y;
    if (std::hypot(dx, dy) >= kMinSegmentM) return std::atan2(dy, dx);
  }
  return fallback;
}

}  // namespace

PolylineElement RankElement(const Grid& grid, CellIndex first, CellIndex last, int tag) {
  PolylineElement e;
  e.kind = TourElementKind::kRank;
  e.points = {grid.CellCenter(first), grid.CellCenter(last)};
  e.kinds = {SegmentKind::kCoverage};
  std::vector<CellIndex> cells;
  const bool h = first.row == last.row;
  const int n = h ? last.col - first.col + 1 : last.row - first.row + 1;
  for (int k = 0; k < n; ++k)
    cells.push_back(h ? CellIndex{first.row, first.col + k} : CellIndex{first.row + k, first.col});
  e.sweeps = {std::move(cells)};
  e.tags = {tag};
  e.first_cell = first;
  e.last_cell = last;
  return e;
}

bool IsWellFormed(const PolylineElement& el) {
  return el.points.size() >= 2 && el.kinds.size() + 1 == el.points.size() &&
         el.sweeps.size() == el.kinds.size() && el.tags.size() == el.kinds.size();
}

ElementVariant PolylineVariant(const std::vector<Point2>& pts, const std::vector<Point2>& rev,
                               double fallback_in, double fallback_back, const MotionCost& motion) {
  ElementVariant v;
  v.heading_in = FirstHeading(pts, fallback_in);
  v.heading_out = std::fmod(FirstHeading(rev, fallback_back) + M_PI, 2 * M_PI);
  v.traverse = motion.Polyline(pts, v.heading_in, std::nullopt);
  return v;
}

void DrivePolyline(const PolylineElement& el, bool forward, double heading_in,
                   TourPathWriter* writer) {
  const int segs = static_cast<int>(el.kinds.size());
  writer->Turn(heading_in);
  for (int k = 0; k < segs; ++k) {
    const int s = forward ? k : segs - 1 - k;
    writer->Segment(forward ? el.points[s + 1] : el.points[s], el.kinds[s], el.tags[s],
                    el.sweeps[s]);
  }
}

absl::StatusOr<PolylineTourModel> PolylineTourModel::Create(
    const Grid& drive, std::vector<PolylineElement> elements, const Pose2& start,
    std::optional<Pose2> end, std::shared_ptr<const MotionCost> motion, const StopToken& stop,
    int num_threads) {
  if (elements.empty()) return absl::InvalidArgumentError("no tour elements");
  if (motion == nullptr) return absl::InvalidArgumentError("no motion cost");
  PolylineTourModel m;
  m.SetPoses(start, end, std::move(motion));
  std::vector<CellIndex> endpoints;
  for (size_t e = 0; e < elements.size(); ++e) {
    if (!IsWellFormed(elements[e])) {
      return absl::InvalidArgumentError(absl::StrFormat("tour element %d is malformed", e));
    }
    endpoints.push_back(elements[e].first_cell);
    endpoints.push_back(elements[e].last_cell);
  }
  m.elements_ = std::move(elements);
  m.IndexVertices();
  RETURN_IF_ERROR(m.BuildTable(drive, std::move(endpoints), stop, num_threads));
  std::vector<ElementVariant> variants(m.num_vertices());
  for (int e = 0; e < m.num_elements(); ++e) {
    const PolylineElement& el = m.elements_[e];
    std::vector<Point2> bwd = el.points;
    std::reverse(bwd.begin(), bwd.end());
    const double axis = el.first_cell.row == el.last_cell.row ? 0.0 : M_PI / 2;
    variants[2 * e] = PolylineVariant(el.points, bwd, axis, axis + M_PI, m.motion());
    variants[2 * e + 1] = PolylineVariant(bwd, el.points, axis + M_PI, axis, m.motion());
  }
  m.SetVariants(std::move(variants));
  RETURN_IF_ERROR(m.RoutePoses(stop, "start", "end"));
  return m;
}

absl::Status PolylineTourModel::Unreachable(int element) const {
  return absl::FailedPreconditionError(
      absl::StrFormat("tour element %d cannot be reached from the start", element));
}

void PolylineTourModel::DriveVariant(int v, TourPathWriter* writer) const {
  DrivePolyline(elements_[v / 2], v % 2 == 0, heading_in(v), writer);
}

}  // namespace covplan
