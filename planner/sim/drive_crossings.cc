// SimulatedDrive and the obstacles smaller than their cells: the robot finds
// one on its path ahead by sight (RangeSensor::Sees) or by touch and reports
// its cell, as it reports a blocked cell.
#include <cstdint>
#include <optional>
#include <vector>

#include "planner/sim/drive.h"
#include "planner/tour/grid_paths.h"

namespace covplan::sim_internal {

void SimulatedDrive::FindCrossings() {
  crossings_ = SmallObstacleCrossings(truth_, grid_, path());
  stranding_.assign(found_.size(), 0);
}

bool SimulatedDrive::Ahead(const PathCrossing& x) const {
  if (x.segment < seg_ || (x.segment == seg_ && x.along_m < d_seg_)) return false;
  const int64_t cell = Index(x.cell);
  return !found_[cell] && !stranding_[cell];
}

bool SimulatedDrive::Strands(const PathCrossing& x) {
  const int64_t cell = Index(x.cell);
  const Grid& drive =
      plan_.area != nullptr && plan_.area->drive != nullptr ? *plan_.area->drive : *plan_.plan.grid;
  if (drive.size() != grid_.size()) return false;
  // The robot's cell model with the cell closed: every cell it has still to
  // sweep stays in the robot's component.
  std::vector<uint8_t> free = drive.free_flags();
  for (size_t i = 0; i < free.size(); ++i) free[i] = free[i] && !found_[i];
  free[static_cast<size_t>(cell)] = 0;
  const Grid closed = drive.WithFreeFlags(std::move(free));
  int32_t n = 0;
  const std::vector<int32_t> comp = FreeComponents(closed, &n);
  // The robot joins the closed grid where the replanner would put it: in
  // its own cell, or (that cell closed) the free neighbour JoinCell picks,
  // which it must reach without crossing another closed cell (a neighbour
  // only diagonally reachable past two closed cells does not count: the
  // way out would clip a reported cell).
  const Pose2 robot_pose{pos_.x, pos_.y, 0.0};
  const absl::StatusOr<CellIndex> at = JoinCell(closed, robot_pose, "robot");
  const int32_t robot =
      at.ok() && ClearJoin(closed, robot_pose, *at) ? comp[closed.Index(at->row, at->col)] : -1;
  if (robot < 0) return stranding_[cell] = 1, true;
  for (const CoverageSweep& s : plan_.plan.sweeps) {
    if (s.waypoint < seg_) continue;
    for (const CellIndex& c : s.cells) {
      const int64_t i = Index(c);
      if (i == cell || swept_[i] || found_[i] || comp[i] == robot) continue;
      stranding_[cell] = 1;
      return true;
    }
  }
  return false;
}

void SimulatedDrive::SenseCrossings() {
  for (const PathCrossing& x : crossings_) {
    if (!Ahead(x) || !sensor_.Sees(pos_, x.at) || Strands(x)) continue;
    ++r_.num_small_obstacles;
    Observe(x.cell);
  }
}

std::optional<CellIndex> SimulatedDrive::TouchCrossing(double d) {
  for (const PathCrossing& x : crossings_) {
    if (x.segment > seg_) break;
    if (x.segment == seg_ && x.along_m <= d && Ahead(x) && !Strands(x)) {
      ++r_.num_small_obstacles;
      return x.cell;
    }
  }
  return std::nullopt;
}

}  // namespace covplan::sim_internal
