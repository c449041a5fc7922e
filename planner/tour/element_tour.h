// The plumbing every tour model over drivable elements shares: the
// transition table between the variants' end cells, the routes from the
// start pose and to the end pose, the price of every move and the writing of
// an ordered tour's waypoints. Variant v of an element is entered at
// transition-table endpoint v and left at endpoint v ^ 1, so variants come
// in pairs: one piece (a rank, a kept piece of an old path, an ox-plow path)
// driven either way. A model (RankTourCost, PolylineTourModel,
// CellTourModel) adds only what is its own: its elements, each variant's
// headings and traversal cost, how a variant is driven and how it names an
// element the start cannot reach.
//
//   // in MyModel::Create, once the elements are in place:
//   m.IndexVertices();
//   RETURN_IF_ERROR(m.BuildTable(drive, std::move(endpoints), stop, threads));
//   m.SetPoses(start, end, std::move(motion));
//   m.SetVariants(std::move(variants));
//   RETURN_IF_ERROR(m.RoutePoses(stop, "start", "end"));
//   // later: m.BuildPath(order.vertices, &path, &sweeps);
//
// Thread-safety: a model is immutable once built and its const methods are
// thread-safe; a TourPathWriter is single-threaded.
#ifndef COVPLAN_PLANNER_TOUR_ELEMENT_TOUR_H_
#define COVPLAN_PLANNER_TOUR_ELEMENT_TOUR_H_

#include <memory>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/tour_model.h"
#include "planner/tour/transitions.h"

namespace covplan {

// Writes a tour's waypoints from its start pose: transitions given as point
// lists, coverage as straight ranks or as segments of a polyline.
class TourPathWriter {
 public:
  // Begins `path` with the kStart waypoint at `start`. `sweeps` receives one
  // sweep per coverage Segment; it may be null when only Cover is used.
  TourPathWriter(const Pose2& start, std::vector<Waypoint>* path,
                 std::vector<CoverageSweep>* sweeps);
  // Drives pts[1..] as transition segments (pts[0] is where the robot is),
  // skipping points closer than kMinSegmentM to the robot.
  void Transit(const std::vector<Point2>& pts);
  // One coverage segment to `to` along `heading` (a straight rank: the robot
  // turns onto it even when it has zero length).
  void Cover(Point2 to, double heading, int tag);
  // Sets the heading the next Segment keeps when it is degenerate.
  void Turn(double heading) { heading_ = heading; }
  // A segment of `kind` to `to`; a coverage one is kept even when shorter
  // than kMinSegmentM and carries `tag` and the `cells` it sweeps.
  void Segment(Point2 to, SegmentKind kind, int tag, const std::vector<CellIndex>& cells);

 private:
  Point2 at_;
  double heading_;
  std::vector<Waypoint>* path_;
  std::vector<CoverageSweep>* sweeps_;
};

// How a variant is driven: the heading where it is entered and left, and
// the cost of driving it.
struct ElementVariant {
  double heading_in = 0.0;
  double heading_out = 0.0;
  double traverse = 0.0;
};

class ElementTourModel : public TourModel {
 public:
  bool has_end() const final { return has_end_; }
  double FromStart(int v) const final { return from_start_[v]; }
  // Drives the table's path from the exit of u to the entry of v, turning
  // from u's exit heading and onto v's entry heading, then traverses v.
  double Between(int u, int v) const final;
  double ToEnd(int u) const final { return to_end_[u]; }

  const Pose2& start() const { return start_; }
  double heading_in(int v) const { return variants_[v].heading_in; }
  // Time spent building the table (when the model built its own) and
  // routing the poses.
  double transitions_ms() const { return transitions_ms_; }
  // The waypoints (starting with the start pose) and the coverage sweeps of
  // a tour given as one vertex per element.
  void BuildPath(const std::vector<int>& vertices, std::vector<Waypoint>* path,
                 std::vector<CoverageSweep>* sweeps) const;

 protected:
  ElementTourModel() = default;

  // Drives variant v from its entry (where the writer stands) to its exit.
  virtual void DriveVariant(int v, TourPathWriter* writer) const = 0;
  // The error for an element whose entry the start pose cannot reach.
  virtual absl::Status Unreachable(int element) const = 0;

  // The table over `endpoints` (2 per variant pair: entry of v, then exit).
  absl::Status BuildTable(const Grid& drive, std::vector<CellIndex> endpoints,
                          const StopToken& stop, int num_threads);
  // A table built elsewhere, which must outlive the model.
  void UseTable(const Grid& drive, const TransitionTable& table);
  // `end` absent: the tour returns to the start.
  void SetPoses(const Pose2& start, std::optional<Pose2> end,
                std::shared_ptr<const MotionCost> motion);
  const MotionCost& motion() const { return *motion_; }
  // The centre of the cell where variant v is left.
  Point2 ExitPoint(int v) const { return grid_->CellCenter(table_->endpoint(v ^ 1)); }
  void SetVariants(std::vector<ElementVariant> variants) { variants_ = std::move(variants); }
  // Joins the poses to the grid and prices the legs from the start and to
  // the end (infinite for an exit the end cannot reach). Errors name the
  // poses `start_name` / `end_name`.
  absl::Status RoutePoses(const StopToken& stop, const char* start_name, const char* end_name);

 private:
  // The cell centres of the path from the exit of u to the entry of v, and
  // its time: the table's path, or the reverse of the table's path from v's
  // entry to u's exit when that one takes less time with the two headings.
  double TransitionPoints(int u, int v, std::vector<Point2>* pts) const;

  const Grid* grid_ = nullptr;
  const TransitionTable* table_ = nullptr;
  std::shared_ptr<const TransitionTable> own_table_;  // when built by BuildTable
  std::shared_ptr<const MotionCost> motion_;
  Pose2 start_;
  Pose2 end_;
  bool has_end_ = false;
  std::vector<ElementVariant> variants_;  // per vertex
  std::vector<double> from_start_, to_end_;
  // Paths start -> entry and exit -> end, as points.
  std::vector<std::vector<Point2>> start_paths_, end_paths_;
  absl::Time table_started_;
  double transitions_ms_ = 0.0;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_ELEMENT_TOUR_H_
