#include "planner/stc/spanning_tree.h"

#include <utility>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/prim_minimum_spanning_tree.hpp>

namespace covplan {
namespace {

void AddEdge(StcTree* tree, const CoarseGrid& coarse, int cell, int side) {
  tree->sides[cell] |= 1 << side;
  tree->sides[coarse.Neighbour(cell, side)] |= 1 << ((side + 2) % 4);
  ++tree->num_edges;
}

// The root of every component: `root` first, then each unreached node in
// row-major order (calls `grow` for each).
template <typename Grow>
StcTree GrowForest(const CoarseGrid& coarse, StcRoot root, Grow grow) {
  StcTree tree;
  tree.sides.assign(coarse.size(), 0);
  std::vector<uint8_t> seen(coarse.size(), 0);
  auto start = [&](StcRoot r) {
    tree.roots.push_back(r);
    grow(r, &seen, &tree);
  };
  if (coarse.IsNode(root.cell)) start(root);
  for (int id = 0; id < coarse.size(); ++id) {
    if (coarse.IsNode(id) && !seen[id]) start({id, 0});
  }
  for (int id = 0; id < coarse.size(); ++id) tree.num_nodes += seen[id];
  return tree;
}

}  // namespace

StcTree BuildDfsTree(const CoarseGrid& coarse, StcRoot root) {
  return GrowForest(coarse, root, [&](StcRoot r, std::vector<uint8_t>* seen, StcTree* tree) {
    struct Frame {
      int cell;
      int first_side;
      int count;
      int i;
    };
    std::vector<Frame> stack = {{r.cell, r.position, 4, 0}};
    (*seen)[r.cell] = 1;
    while (!stack.empty()) {
      Frame& f = stack.back();
      if (f.i == f.count) {
        stack.pop_back();
        continue;
      }
      const int side = (f.first_side + f.i++) % 4;
      if (!coarse.CanLink(f.cell, side)) continue;
      const int next = coarse.Neighbour(f.cell, side);
      if ((*seen)[next]) continue;
      (*seen)[next] = 1;
      AddEdge(tree, coarse, f.cell, side);
      // Entered across its side facing us; scan the other three after it.
      const int back = (side + 2) % 4;
      stack.push_back({next, (back + 1) % 4, 3, 0});
    }
  });
}

StcTree BuildPrimTree(const CoarseGrid& coarse, StcRoot root, SweepDirection direction) {
  using Graph =
      boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS, boost::no_property,
                            boost::property<boost::edge_weight_t, double>>;
  return GrowForest(coarse, root, [&](StcRoot r, std::vector<uint8_t>* seen, StcTree* tree) {
    // The component of r (BFS), numbered locally.
    std::vector<int> cells = {r.cell};
    std::vector<int> local(coarse.size(), -1);
    local[r.cell] = 0;
    (*seen)[r.cell] = 1;
    for (size_t head = 0; head < cells.size(); ++head) {
      for (int side = 0; side < 4; ++side) {
        if (!coarse.CanLink(cells[head], side)) continue;
        const int next = coarse.Neighbour(cells[head], side);
        if (local[next] >= 0) continue;
        local[next] = static_cast<int>(cells.size());
        (*seen)[next] = 1;
        cells.push_back(next);
      }
    }
    Graph g(cells.size());
    for (int cell : cells) {
      for (int side : {1, 2}) {  // east and north: each edge once
        if (!coarse.CanLink(cell, side)) continue;
        const bool along = (side == 1) == (direction == SweepDirection::kHorizontal);
        const bool clean =
            coarse.Crossable(cell, side, side) && coarse.Crossable(cell, side, (side + 1) % 4);
        boost::add_edge(local[cell], local[coarse.Neighbour(cell, side)],
                        (along ? 1.0 : 2.0) + (clean ? 0.0 : 2.0), g);
      }
    }
    std::vector<Graph::vertex_descriptor> pred(cells.size());
    boost::prim_minimum_spanning_tree(g, pred.data(), boost::root_vertex(0));
    for (size_t v = 0; v < cells.size(); ++v) {
      if (pred[v] == v) continue;
      const int a = cells[v], b = cells[pred[v]];
      for (int side = 0; side < 4; ++side) {
        if (coarse.Neighbour(a, side) == b) AddEdge(tree, coarse, a, side);
      }
    }
  });
}

std::vector<std::vector<CellIndex>> CircumnavigateEach(const CoarseGrid& coarse,
                                                       const StcTree& tree) {
  std::vector<std::vector<CellIndex>> rings;
  for (const StcRoot& root : tree.roots) {
    std::vector<CellIndex>& ring = rings.emplace_back();
    StcRoot at = root;
    do {
      ring.push_back(coarse.SubCell(at.cell, at.position));
      at = NextOnRing(coarse, tree, at);
    } while (at.cell != root.cell || at.position != root.position);
  }
  return rings;
}

std::vector<CellIndex> Circumnavigate(const CoarseGrid& coarse, const StcTree& tree) {
  std::vector<CellIndex> out;
  out.reserve(static_cast<size_t>(tree.num_nodes) * 4);
  for (const std::vector<CellIndex>& ring : CircumnavigateEach(coarse, tree)) {
    out.insert(out.end(), ring.begin(), ring.end());
  }
  return out;
}

}  // namespace covplan
