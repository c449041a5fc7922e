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
#include <utility>
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
// boundaries (the moves the line-of-sight rule allows). Returns per-cell component id, -1 for
// blocked.
std::vector<int32_t> FreeComponents(const Grid& grid, int32_t* num_components);

// True when the straight segment a-b (map frame) touches a cell for which
// closed(row, col) holds: cells entered, clipped, or met at an exact grid
// corner (all four cells around it count, as in LineOfSight).
bool SegmentTouches(const Grid& frame, Point2 a, Point2 b,
                    const std::function<bool(int, int)>& closed);

// The free cell where a robot at `pose` joins the grid: its own cell, or,
// when that cell is blocked (a dock against a wall stands in a cell that is
// mostly wall, or a new obstacle covers the robot's cell), the adjacent free
// cell whose centre is nearest among those the straight move from the pose
// reaches without touching another blocked cell (a diagonal move must not
// cut a wall's corner); the nearest adjacent free cell if none does. `what`
// names the pose in the InvalidArgument error ("start", "end").
absl::StatusOr<CellIndex> JoinCell(const Grid& grid, const Pose2& pose, const char* what);

// Whether the straight move from `pose` to the centre of `cell` touches no
// blocked cell but the pose's own (JoinCell's test of an adjacent cell; its
// last resort, the nearest adjacent free cell, may fail it).
bool ClearJoin(const Grid& grid, const Pose2& pose, CellIndex cell);

// The moves the drive searches allow from a cell, as bit k of a mask for
// the step (kDriveDr[k], kDriveDc[k]): 4-neighbours (k < 4) through passable
// boundaries, and diagonals (k >= 4) whose two L-shaped routes are open (no
// corner cutting) and whose segment touches no non-free map pixel.
inline constexpr int kDriveDr[8] = {1, -1, 0, 0, 1, 1, -1, -1};
inline constexpr int kDriveDc[8] = {0, 0, 1, -1, 1, -1, 1, -1};
uint8_t DriveMoveMask(const Grid& g, CellIndex c);

// Calls f(neighbour index, diagonal?) for every move of DriveMoveMask, in
// the order of k.
template <typename F>
void ForEachDriveMove(const Grid& g, CellIndex c, F&& f) {
  const uint8_t mask = DriveMoveMask(g, c);
  for (int k = 0; k < 8; ++k) {
    if (mask >> k & 1) f(g.Index(c.row + kDriveDr[k], c.col + kDriveDc[k]), k >= 4);
  }
}

class AnyAngleSearch {
 public:
  explicit AnyAngleSearch(const Grid& grid);

  // Returns false if stopped early (results then incomplete).
  bool Run(CellIndex source, const StopToken& stop);
  // Goal-directed (A*, Euclidean heuristic) search that stops once `target`
  // is settled; afterwards PathTo(target) and DistanceCells(target) hold.
  // Costs only the cells it touches (no whole-grid reset), so many short
  // searches on a large grid stay cheap. False if stopped early, or after
  // `max_expansions` expansions: then `*bound` (if given) is a lower bound
  // of the distance (the smallest g + h still open). A call for the same
  // source and target right after one that ended at `max_expansions` goes on
  // from where it stopped (the result is that of one uninterrupted search).
  bool RunTo(CellIndex source, CellIndex target, const StopToken& stop,
             int64_t max_expansions = INT64_MAX, float* bound = nullptr);
  // Run() cut short: the same search (same order, same distances) that
  // calls settle(cell index, distance) for each cell it closes and stops when
  // settle returns false or `max_settled` cells are closed. Costs only the
  // cells it touches. False if stopped early.
  bool Explore(CellIndex source, int64_t max_settled, const StopToken& stop,
               const std::function<bool(int64_t, float)>& settle);
  bool Reached(CellIndex c) const { return dist_[grid_.Index(c.row, c.col)] < kUnreached; }
  // Path length in cell units (multiply by cell size for metres).
  double DistanceCells(CellIndex c) const { return dist_[grid_.Index(c.row, c.col)]; }
  // After RunTo or Explore: f(cell index) for every cell it closed, whose
  // distance and path (PathTo) are then final.
  template <typename F>
  void ForEachClosed(F&& f) const {
    for (int32_t i : touched_) {
      if (closed_[i]) f(static_cast<int64_t>(i));
    }
  }
  // Corner cells from the source to `target`, both included; empty if unreached.
  std::vector<CellIndex> PathTo(CellIndex target) const;
  // LineOfSight(grid, a, b), read from the search's per-cell move masks
  // (filled on first use) instead of the grid: what the searches call.
  bool Visible(CellIndex a, CellIndex b);
  // Scratch bytes per grid cell (distance, parent, closed flag, touched
  // list, move mask).
  static constexpr int64_t kBytesPerCell = 15;

 private:
  static constexpr float kUnreached = 1e30f;
  // moves_ bits: 0-7 DriveMoveMask, kDirty the cell overlaps a non-free map
  // pixel, kKnown the entry is filled (cells are filled when first met).
  static constexpr uint16_t kDirty = 1u << 8, kKnown = 1u << 9;
  const Grid& grid_;
  std::vector<float> dist_;
  std::vector<int32_t> parent_;
  std::vector<uint8_t> closed_;
  std::vector<uint16_t> moves_;
  std::vector<std::pair<float, int32_t>> open_;  // RunTo's heap (g + h, cell)
  int64_t expansions_ = 0;                       // RunTo's, kept to resume
  int64_t goal_ = -1;
  bool resumable_ = false;        // the last RunTo stopped at its max_expansions
  std::vector<int32_t> touched_;  // cells written by the last RunTo
  bool all_dirty_ = false;        // Run wrote the whole grid
  int64_t source_ = -1;
  void Reset();
  uint16_t Moves(int64_t i, CellIndex c) {
    const uint16_t m = moves_[i];
    return (m & kKnown) ? m : FillMoves(i, c);
  }
  uint16_t FillMoves(int64_t i, CellIndex c);
  // Lazy Theta*'s parent repair and any-angle relaxation (grid_paths.cc).
  void RepairParent(int32_t s, CellIndex cs);
  template <typename F>
  void RelaxThroughParent(int32_t s, CellIndex cs, F&& improved);
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_GRID_PATHS_H_
