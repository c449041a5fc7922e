// A TourModel over elements that are polylines through cell centres: a rank
// (two points), a kept piece of an old path (many points, with its own
// coverage and transition segments), a cell, a station. Each element can be
// driven forwards or backwards (two variants). Moves between elements are
// any-angle transitions on the drive grid; everything is priced by the
// injected MotionCost. This is the model TOUR-REPLAN solves (path sets and
// rank sets of the thesis), and any planner can use it for its own units;
// the helpers below serve every model whose variants are polylines.
//
//   std::vector<PolylineElement> elements = ...;
//   ASSIGN_OR_RETURN(PolylineTourModel model,
//                    PolylineTourModel::Create(drive, std::move(elements), start, end, motion,
//                    stop, 2));
//   ASSIGN_OR_RETURN(TourOrder order, GtspOrderer(opts).Order(model, stop));
//   model.BuildPath(order.vertices, &path, &sweeps);
//
// Vertex 2e is element e forwards, 2e + 1 backwards.
// Thread-safety: immutable after Create.
#ifndef COVPLAN_PLANNER_TOUR_POLYLINE_TOUR_H_
#define COVPLAN_PLANNER_TOUR_POLYLINE_TOUR_H_

#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/grid/grid.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/element_tour.h"
#include "planner/tour/tour_model.h"

namespace covplan {

struct PolylineElement {
  TourElementKind kind = TourElementKind::kRank;
  // Forward order. points.front() / points.back() are the centres of
  // first_cell / last_cell, where transitions join.
  std::vector<Point2> points;
  std::vector<SegmentKind> kinds;              // per segment: points.size() - 1 entries
  std::vector<std::vector<CellIndex>> sweeps;  // per segment: cells swept (coverage only)
  std::vector<int> tags;                       // per segment: Waypoint::rank of the segment
  CellIndex first_cell, last_cell;
};

// A rank as a two-point polyline element.
PolylineElement RankElement(const Grid& grid, CellIndex first, CellIndex last, int tag);

// True when `el` has a segment and one kind, sweep and tag per segment.
bool IsWellFormed(const PolylineElement& el);

// The variant that drives `pts` (`rev` is the same points reversed): it is
// entered along its first segment of at least kMinSegmentM (`fallback_in`
// if there is none), left along the last one (`fallback_back` is rev's
// fallback heading), and costs `motion` along `pts`.
ElementVariant PolylineVariant(const std::vector<Point2>& pts, const std::vector<Point2>& rev,
                               double fallback_in, double fallback_back, const MotionCost& motion);

// Drives `el` from the end it is entered at, heading `heading_in` there
// (coverage segments keep their tags and sweeps).
void DrivePolyline(const PolylineElement& el, bool forward, double heading_in,
                   TourPathWriter* writer);

class PolylineTourModel final : public ElementTourModel {
 public:
  // InvalidArgument when an element is malformed or the start or end pose is
  // off the drive grid; FailedPrecondition when an element cannot be reached
  // from the start.
  static absl::StatusOr<PolylineTourModel> Create(const Grid& drive,
                                                  std::vector<PolylineElement> elements,
                                                  const Pose2& start, std::optional<Pose2> end,
                                                  std::shared_ptr<const MotionCost> motion,
                                                  const StopToken& stop, int num_threads);

  int num_elements() const override { return static_cast<int>(elements_.size()); }
  int num_variants(int) const override { return 2; }
  TourElementKind kind(int e) const override { return elements_[e].kind; }
  const std::vector<PolylineElement>& elements() const { return elements_; }

 private:
  PolylineTourModel() = default;
  void DriveVariant(int v, TourPathWriter* writer) const override;
  absl::Status Unreachable(int element) const override;

  std::vector<PolylineElement> elements_;  // table endpoint 2e = first cell, 2e + 1 = last cell
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_POLYLINE_TOUR_H_
