// Tours over generic tour elements. A tour visits every element once, in one
// of its variants: a rank in either direction, a kept piece of an old path
// in either direction, a cell with its entry/exit options, a station. A
// TourModel prices the moves between variants with an injected MotionCost
// (travel time today, energy later); one builder turns any TourModel into
// the GTSP instance (one set per element, one vertex per variant, a start
// vertex and an optional end vertex with a zero-cost arc end -> start), and
// the orderers solve it.
//
//   RankTourCost model = ...;              // a TourModel over ranks
//   ASSIGN_OR_RETURN(TourOrder order, GtspOrderer(opts).Order(model, stop));
//
// Vertex ids are element-major: element e's variants are
// [first_vertex(e), first_vertex(e) + num_variants(e)).
// Thread-safety: models are immutable once built; orderers are stateless
// apart from their options.
#ifndef COVPLAN_PLANNER_TOUR_TOUR_MODEL_H_
#define COVPLAN_PLANNER_TOUR_TOUR_MODEL_H_

#include <optional>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/robot_model.h"

namespace covplan {

// The price of driving: a polyline with the headings at its ends.
class MotionCost {
 public:
  virtual ~MotionCost() = default;
  virtual std::string_view unit() const = 0;  // "s", "Wh", ...
  // Cost of driving through `points`; `heading_in` is the heading at
  // points[0] (no initial turn if absent), `heading_out` adds a final turn.
  virtual double Polyline(const std::vector<Point2>& points, std::optional<double> heading_in,
                          std::optional<double> heading_out) const = 0;
  // Cost of one straight segment of `length_m` from rest to rest.
  virtual double Straight(double length_m) const = 0;
};

// Seconds under the robot's time model (planner/tour/path_timing.h).
class TravelTimeCost final : public MotionCost {
 public:
  explicit TravelTimeCost(const RobotModel& robot) : robot_(robot) {}
  std::string_view unit() const override { return "s"; }
  double Polyline(const std::vector<Point2>& points, std::optional<double> heading_in,
                  std::optional<double> heading_out) const override;
  double Straight(double length_m) const override { return robot_.StraightTime(length_m); }

 private:
  RobotModel robot_;
};

enum class TourElementKind { kRank, kPathPiece, kCell, kStation };

class TourModel {
 public:
  virtual ~TourModel() = default;
  virtual int num_elements() const = 0;
  virtual int num_variants(int element) const = 0;
  virtual TourElementKind kind(int element) const = 0;
  virtual bool has_end() const = 0;
  // Cost from the start to the entry of v, plus traversing v.
  virtual double FromStart(int v) const = 0;
  // Cost from the exit of u to the entry of v, plus traversing v
  // (infinity when v cannot follow u, e.g. the same element).
  virtual double Between(int u, int v) const = 0;
  // Cost from the exit of u to the end (the start if there is no end).
  virtual double ToEnd(int u) const = 0;

  int num_vertices() const;
  int first_vertex(int element) const;
  int element_of(int vertex) const;
  // Cost of a tour given as one vertex per element in visiting order.
  double TourCost(const std::vector<int>& vertices) const;

 protected:
  // Call once the element count and variants are known.
  void IndexVertices();

 private:
  std::vector<int> first_;  // per element, plus the total
  std::vector<int> element_of_;
};

struct TourOrder {
  std::vector<int> vertices;   // one vertex per element, visiting order
  double cost = 0.0;           // TourModel::TourCost(vertices)
  bool stopped_early = false;  // a limit (time limit or request stop) ended the search
  Termination termination;
};

struct OrdererOptions {
  double time_limit_s = 1.0;
  uint64_t seed = 1;
  int num_threads = 1;
  GtspEffort effort = GtspEffort::kDefault;
  // A remembered order of this model's elements (one vertex per element,
  // e.g. the tour of the same map from another start pose). GtspOrderer then
  // starts from its best rotation (or its reversal's: the start/end arcs
  // moved, the cycle between them did not) instead of the greedy tour, and
  // runs `warm_trials` warm trials (kEffortTrials: the effort's count; 0:
  // only the local step). Ignored when it does not fit the model.
  std::vector<int> warm_order = {};
  int warm_trials = 1;
  static constexpr int kEffortTrials = -1;
};

class TourOrderer {
 public:
  virtual ~TourOrderer() = default;
  virtual std::string_view name() const = 0;
  // `stop` is the request's token; the orderer's own time limit is merged in.
  virtual absl::StatusOr<TourOrder> Order(const TourModel& model, const StopToken& stop) const = 0;
};

// Nearest unvisited element (cheapest variant) from the current position.
class GreedyOrderer final : public TourOrderer {
 public:
  std::string_view name() const override { return "greedy"; }
  absl::StatusOr<TourOrder> Order(const TourModel& model, const StopToken& stop) const override;
};

// Anytime GTSP over the model, warm-started from the greedy tour.
class GtspOrderer final : public TourOrderer {
 public:
  explicit GtspOrderer(OrdererOptions options) : options_(options) {}
  std::string_view name() const override { return "gtsp"; }
  absl::StatusOr<TourOrder> Order(const TourModel& model, const StopToken& stop) const override;

 private:
  OrdererOptions options_;
};

// The cheapest of the rotations of `order` and of its reversal (each
// element driven in its other variant, when it has exactly two), or empty
// when `order` is not one vertex per element of `model`.
std::vector<int> BestRotation(const TourModel& model, const std::vector<int>& order);

// The GTSP instance of a model: vertices 0..n-1 are the model's, n is the
// start and n + 1 the end (when the model has one). False when `stop` fired.
bool BuildGtspInstance(const TourModel& model, const StopToken& stop, GtspInstance* out);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_TOUR_MODEL_H_
