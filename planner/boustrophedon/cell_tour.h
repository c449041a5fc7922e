// The tour over boustrophedon cells: each cell is one tour element with four
// variants, its ox-plow path started from either end of its first line
// (plain or mirrored) and driven forwards or backwards, so the tour may
// enter a cell at any of its four corners and leave at the matching
// opposite one. Moves between cells are any-angle transitions on the drive
// grid between the variants' end cells, priced by the injected MotionCost
// (travel time), by the plumbing of planner/tour/element_tour.h.
//
//   std::vector<std::array<PolylineElement, 2>> cells = ...;  // plain, mirrored
//   ASSIGN_OR_RETURN(CellTourModel model, CellTourModel::Create(drive, std::move(cells), start,
//   end,
//                                                               motion, stop, threads));
//   ASSIGN_OR_RETURN(TourOrder order, GtspOrderer(opts).Order(model, stop));
//   model.BuildPath(order.vertices, &path, &sweeps);
//
// Vertex 4e + 2m + d: cell e, ox-plow m (0 plain, 1 mirrored), d = 1 driven
// backwards. Thread-safety: immutable after Create.
#ifndef COVPLAN_PLANNER_BOUSTROPHEDON_CELL_TOUR_H_
#define COVPLAN_PLANNER_BOUSTROPHEDON_CELL_TOUR_H_

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/grid/grid.h"
#include "planner/tour/element_tour.h"
#include "planner/tour/polyline_tour.h"
#include "planner/tour/tour_model.h"

namespace covplan {

class CellTourModel final : public ElementTourModel {
 public:
  // InvalidArgument for malformed elements or a start/end off the drive
  // grid; FailedPrecondition when a cell cannot be reached from the start.
  static absl::StatusOr<CellTourModel> Create(const Grid& drive,
                                              std::vector<std::array<PolylineElement, 2>> cells,
                                              const Pose2& start, std::optional<Pose2> end,
                                              std::shared_ptr<const MotionCost> motion,
                                              const StopToken& stop, int num_threads);

  int num_elements() const override { return static_cast<int>(cells_.size()); }
  int num_variants(int) const override { return 4; }
  TourElementKind kind(int) const override { return TourElementKind::kCell; }

 private:
  CellTourModel() = default;
  const PolylineElement& Element(int v) const { return cells_[v / 4][(v / 2) % 2]; }
  void DriveVariant(int v, TourPathWriter* writer) const override;
  absl::Status Unreachable(int element) const override;

  // Table endpoint 2p = first cell, 2p + 1 = last cell of ox-plow p = 2e + m.
  std::vector<std::array<PolylineElement, 2>> cells_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_BOUSTROPHEDON_CELL_TOUR_H_
