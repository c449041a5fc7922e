// Obstacle-free paths on the tool-width grid.
//
// The robot drives between cell centres. A straight segment is allowed when
// every cell it touches is free and every cell boundary it crosses is
// passable (no thin-wall barrier); through an exact grid corner, all four
// cells and boundaries around it must be open. For grids built from a map,
// the segment must also touch no non-free map pixel (ObstaclePixels), so a
// path's centre line never crosses an obstacle the cell grid cannot show.
// AnyAngleSearch is a single-source Lazy Theta* (Nash, Koenig & Tovey 2010)
// without a goal: one search yields any-angle shortest paths, as chains of
// corner cells, from the source to every reachable cell.
//
//   AnyAngleSearch search(grid);
//   search.Run(source, stop);
//   std::vector<CellIndex> corners = search.PathTo(target);  // source..target
//
// Thread-safety: an AnyAngleSearch is single-threaded; LineOfSight is
// stateless.
#ifndef COVPLAN_PLANNER_TOUR_GRID_PATHS_H_
#define COVPLAN_PLANNER_TOUR_GRID_PATHS_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/tour/robot_model.h"

namespace covplan {

// True when the straight segment between the centres of a and b touches only
// free cells, crosses no barrier and touches no non-free map pixel.
bool LineOfSight(const Grid& grid, CellIndex a, CellIndex b);

// Connected components of free cells under 4-connectivity through passable
// boundaries (the moves the line-of-sight rule allows). Returns per-cell component id, -1 for blocked.
std::vector<int32_t> FreeComponents(const Grid& grid, int32_t* num_components);

// True when the straight segment a-b (map frame) touches a cell for which
// closed(row, col) holds: cells entered, clipped, or met at an exact grid
// corner (all four cells around it count, as in LineOfSight).
bool SegmentTouches(const Grid& frame, Point2 a, Point2 b, const std::function<bool(int, int)>& closed);

// The free cell where a robot at `pose` joins the grid: its own cell, or,
// when that cell is blocked (a dock against a wall stands in a cell that is
// mostly wall, or a new obstacle covers the robot's cell), the adjacent free
// cell whose centre is nearest among those the straight move from the pose
// reaches without touching another blocked cell (a diagonal move must not
// cut a wall's corner); the nearest adjacent free cell if none does. `what`
// names the pose in the InvalidArgument error ("start", "end").
absl::StatusOr<CellIndex> JoinCell(const Grid& grid, const Pose2& pose, const char* what);

class AnyAngleSearch {
 public:
  explicit AnyAngleSearch(const Grid& grid);

  // Returns false if stopped early (results then incomplete).
  bool Run(CellIndex source, const StopToken& stop);
  bool Reached(CellIndex c) const { return dist_[grid_.Index(c.row, c.col)] < kUnreached; }
  // Path length in cell units (multiply by cell size for metres).
  double DistanceCells(CellIndex c) const { return dist_[grid_.Index(c.row, c.col)]; }
  // Corner cells from the source to `target`, both included; empty if unreached.
  std::vector<CellIndex> PathTo(CellIndex target) const;

 private:
  static constexpr float kUnreached = 1e30f;
  const Grid& grid_;
  std::vector<float> dist_;
  std::vector<int32_t> parent_;
  std::vector<uint8_t> closed_;
  int64_t source_ = -1;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_GRID_PATHS_H_
