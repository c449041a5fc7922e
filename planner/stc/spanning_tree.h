// The spanning tree of STC over a CoarseGrid, and its circumnavigation.
//
// DFS scans a cell's neighbours counter-clockwise starting after the side it
// was entered by (the paper's on-line order), so the off-line tree equals
// the tree the on-line robot builds as it moves. Prim (Boost.Graph) weighs
// links along the sweep direction 1 and across it 2, plus 2 when only one of
// the two sub-cell links across the side is passable, so the tree grows in
// long lanes along the sweep direction and crosses cleanly where it can.
// A coarse graph that falls apart (only with PartialCells::kDiscard) gets
// one tree per component, in row-major order of their first cell.
//
//   StcTree tree = BuildDfsTree(coarse, root, start_pos);
//   std::vector<CellIndex> ring = Circumnavigate(coarse, tree);  // 4 per node
//
// Thread-safety: pure functions.
#ifndef COVPLAN_PLANNER_STC_SPANNING_TREE_H_
#define COVPLAN_PLANNER_STC_SPANNING_TREE_H_

#include <cstdint>
#include <vector>

#include "planner/stc/coarse_grid.h"

namespace covplan {

enum class StcTreeMethod : uint8_t { kDfs = 0, kPrim = 1 };
enum class SweepDirection : uint8_t { kHorizontal = 0, kVertical = 1 };

struct StcRoot {
  int cell = 0;      // coarse cell id
  int position = 0;  // ring position the walk starts at
};

struct StcTree {
  std::vector<uint8_t> sides;  // per coarse cell: bit k = tree edge across side k
  std::vector<StcRoot> roots;  // one per component; roots[0] is the requested root
  int num_nodes = 0;
  int num_edges = 0;
  bool HasEdge(int cell, int side) const { return (sides[cell] >> side) & 1; }
};

StcTree BuildDfsTree(const CoarseGrid& coarse, StcRoot root);
StcTree BuildPrimTree(const CoarseGrid& coarse, StcRoot root, SweepDirection direction);

// Every sub-cell (4 per node, free or not) in the order the counter-clockwise
// circumnavigation of each tree visits them, starting at its root.
std::vector<CellIndex> Circumnavigate(const CoarseGrid& coarse, const StcTree& tree);
// The same, one ring per tree (roots[i] -> ring i).
std::vector<std::vector<CellIndex>> CircumnavigateEach(const CoarseGrid& coarse,
                                                       const StcTree& tree);

// The next (cell, position) of the circumnavigation after (cell, position).
inline StcRoot NextOnRing(const CoarseGrid& coarse, const StcTree& tree, StcRoot at) {
  if (tree.HasEdge(at.cell, at.position)) {
    return {coarse.Neighbour(at.cell, at.position), (at.position + 3) % 4};
  }
  return {at.cell, (at.position + 1) % 4};
}

}  // namespace covplan

#endif  // COVPLAN_PLANNER_STC_SPANNING_TREE_H_
