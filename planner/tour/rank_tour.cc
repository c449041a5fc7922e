#include "planner/tour/rank_tour.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {

double RankHeading(const Rank& r, bool forward) {
  if (r.orientation == Orientation::kHorizontal) return forward ? 0.0 : M_PI;
  return forward ? M_PI / 2 : -M_PI / 2;
}

Pose2 RankTourStart(const Grid& grid, const std::vector<Rank>& ranks, const RobotModel& robot) {
  if (robot.start) return *robot.start;
  const Point2 p = grid.CellCenter(ranks[0].first);
  return {p.x, p.y, ranks[0].orientation == Orientation::kHorizontal ? 0.0 : M_PI / 2};
}

absl::StatusOr<RankTourCost> RankTourCost::Create(const Grid& grid, const std::vector<Rank>& ranks,
                                                  const TransitionTable& table,
                                                  const RobotModel& robot, const StopToken& stop,
                                                  std::shared_ptr<const MotionCost> motion) {
  if (ranks.empty()) return absl::InvalidArgumentError("no ranks to order");
  if (table.num_endpoints() != static_cast<int>(ranks.size() * 2)) {
    return absl::InvalidArgumentError("transition table does not match the ranks");
  }
  RankTourCost cost;
  cost.ranks_ = &ranks;
  cost.IndexVertices();
  cost.UseTable(grid, table);
  cost.SetPoses(
      RankTourStart(grid, ranks, robot), robot.end,
      motion != nullptr ? std::move(motion) : std::make_shared<const TravelTimeCost>(robot));
  // A rank is driven straight along its axis, entered and left on it.
  std::vector<ElementVariant> variants(cost.num_vertices());
  for (int v = 0; v < cost.num_vertices(); ++v) {
    const Rank& r = ranks[v / 2];
    const double heading = RankHeading(r, v % 2 == 0);
    variants[v] = {heading, heading, cost.motion().Straight((r.NumCells() - 1) * grid.cell_size())};
  }
  cost.SetVariants(std::move(variants));
  RETURN_IF_ERROR(cost.RoutePoses(stop, "start pose", "end pose"));
  return cost;
}

absl::Status RankTourCost::Unreachable(int element) const {
  return absl::InvalidArgumentError(absl::StrFormat(
      "rank %d cannot be reached from the start pose (%.3f, %.3f)", element, start().x, start().y));
}

void RankTourCost::DriveVariant(int v, TourPathWriter* writer) const {
  // Zero length for a single cell, where the robot still turns onto the
  // rank heading.
  writer->Cover(ExitPoint(v), heading_in(v), v / 2);
}

std::vector<Waypoint> RankTourCost::BuildPath(const std::vector<int>& vertices) const {
  std::vector<Waypoint> path;
  ElementTourModel::BuildPath(vertices, &path, /*sweeps=*/nullptr);
  return path;
}

}  // namespace covplan
