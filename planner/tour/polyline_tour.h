// A TourModel over elements that are polylines through cell centres: a rank
// (two points), a kept piece of an old path (many points, with its own
// coverage and transition segments), a cell, a station. Each element can be
// driven forwards or backwards (two variants). Moves between elements are
// any-angle transitions on the drive grid; everything is priced by the
// injected MotionCost. This is the model TOUR-REPLAN solves (path sets and
// rank sets of the thesis), and any planner can use it for its own units.
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
#include "planner/tour/tour_model.h"
#include "planner/tour/transitions.h"

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

class PolylineTourModel final : public TourModel {
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
  bool has_end() const override { return has_end_; }
  double FromStart(int v) const override { return from_start_[v]; }
  double Between(int u, int v) const override;
  double ToEnd(int u) const override { return to_end_[u]; }

  // The waypoints (starting with the start pose) and one sweep per coverage
  // segment, for a tour given as one vertex per element.
  void BuildPath(const std::vector<int>& vertices, std::vector<Waypoint>* path,
                 std::vector<CoverageSweep>* sweeps) const;
  const std::vector<PolylineElement>& elements() const { return elements_; }
  double transitions_ms() const { return transitions_ms_; }

 private:
  PolylineTourModel() = default;
  double HeadingIn(int v) const { return heading_in_[v]; }
  double HeadingOut(int v) const { return heading_out_[v]; }
  // Transition-table endpoints where variant v is entered and left.
  static int EntryEndpoint(int v) { return v; }  // 2e (first cell) forwards, 2e + 1 backwards
  static int ExitEndpoint(int v) { return v ^ 1; }
  void TransitionPoints(int u, int v, std::vector<Point2>* pts) const;

  const Grid* grid_ = nullptr;
  std::vector<PolylineElement> elements_;
  std::shared_ptr<const TransitionTable> table_;  // endpoint 2e = first cell, 2e + 1 = last cell
  std::shared_ptr<const MotionCost> motion_;
  Pose2 start_;
  Pose2 end_;
  bool has_end_ = false;
  std::vector<double> heading_in_, heading_out_, traverse_;  // per vertex
  std::vector<double> from_start_, to_end_;
  std::vector<std::vector<Point2>> start_paths_, end_paths_;
  double transitions_ms_ = 0.0;
};

// Writes a tour's waypoints: transitions given as point lists, and polyline
// elements driven forwards or backwards (coverage segments keep their tags
// and sweeps). Shared by the tour models whose elements are polylines.
class PolylinePathWriter {
 public:
  PolylinePathWriter(const Pose2& start, std::vector<Waypoint>* path,
                     std::vector<CoverageSweep>* sweeps);
  // Drives pts[1..] as transition segments (pts[0] is where the robot is).
  void Transit(const std::vector<Point2>& pts);
  // Drives `el` from the end it is entered at, heading `heading_in` there.
  void Drive(const PolylineElement& el, bool forward, double heading_in);

 private:
  Point2 at_;
  double heading_;
  std::vector<Waypoint>* path_;
  std::vector<CoverageSweep>* sweeps_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_POLYLINE_TOUR_H_
