// Provable lower bounds on the length of drive paths between points of a
// site, for the makespan bound (bounds.h; docs/fleet.md gives the proof).
//
// The squares are the drive grid's cells (side h = the cell), or, on grids
// of more than `max_squares` cells, blocks of f x f cells (h = f cells). A
// square is open when a drive cell in it is free or holds one of `points`
// (a dock in a blocked cell). Two squares are linked when they are
// 8-adjacent and connected, around a grid corner both touch, through the
// open squares around that corner:
//  - on the drive grid, through the passable edges meeting the corner (no
//    thin-wall barrier, Grid::Passable); a square holding a point in a
//    blocked cell connects to every open square around its corners;
//  - on blocks, always (barriers ignored, diagonals cut corners).
// D(p, q) is the number of links of the shortest walk from p's square to
// q's. Every path from p to q that stays on free drive cells and crosses
// from cell to cell as the conformance checks allow (a passable edge, or a
// diagonal with an open L-shaped route) is at least (D - 1) h long.
//
//   GeodesicHops geo(drive, points);
//   geo.Search(0, /*max_hops=*/-1);
//   double len = geo.MinLength(geo.Hops(1));  // <= any drive path 0 -> 1
//
// Thread-safety: Search changes the object; one thread at a time.
#ifndef COVPLAN_PLANNER_FLEET_GEODESIC_H_
#define COVPLAN_PLANNER_FLEET_GEODESIC_H_

#include <cstdint>
#include <vector>

#include "planner/grid/grid.h"

namespace covplan {

class GeodesicHops {
 public:
  GeodesicHops(const Grid& drive, const std::vector<Point2>& points,
               int64_t max_squares = int64_t{1} << 21);

  double side() const { return side_; }
  int factor() const { return factor_; }
  int64_t open_squares() const { return open_squares_; }
  int num_points() const { return static_cast<int>(square_.size()); }
  // The padded index of point i's square, -1 when it lies outside the grid.
  int32_t square(int i) const { return square_[i]; }

  // Breadth-first search over the links from point `from`'s square, at most
  // `max_hops` links deep (negative: no limit). Returns the squares settled.
  int64_t Search(int from, int max_hops);
  int source() const { return source_; }
  // After Search: D from the source to point `to`, or a lower bound of it:
  // 1 + the deepest level settled when the search did not reach `to` (it
  // stopped at max_hops, or no walk leads there); 0 when either point lies
  // outside the grid.
  int Hops(int to) const;
  // The least length of any path between two points `hops` apart.
  double MinLength(int hops) const { return hops > 1 ? (hops - 1) * side_ : 0.0; }

 private:
  void LinkCells(const Grid& drive, const std::vector<uint8_t>& dock);
  void LinkBlocks(const std::vector<uint8_t>& open);

  int factor_ = 1;
  double side_ = 0.0;
  int width_ = 0;  // padded: a border of closed squares all around
  int64_t open_squares_ = 0;
  std::vector<uint8_t> links_;   // per padded square: bit m = linked to step m
  std::vector<int32_t> square_;  // per point
  std::vector<int32_t> dist_;    // per padded square, -1 unsettled
  std::vector<int32_t> queue_;   // the last search's settled squares
  int source_ = -1;
  int deepest_ = 0;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_GEODESIC_H_
