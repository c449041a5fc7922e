#include "planner/partition/mincut_partitioner.h"

#include <cstdint>
#include <utility>
#include <vector>

#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/property_map/property_map.hpp>
#include <boost/range/iterator_range.hpp>

namespace covplan {
namespace {

using CsrGraph =
    boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                       boost::no_property, uint32_t, uint32_t>;
using Traits = boost::graph_traits<CsrGraph>;
using EdgeDesc = Traits::edge_descriptor;

constexpr uint32_t kNone = UINT32_MAX;

// Calls arc(u, v) for every unit-capacity arc of the cut graph
// (algorithms.md §2); s and t are the terminal node ids.
template <typename F>
void ForEachArc(const Grid& grid, const std::vector<uint32_t>& node, uint32_t s, uint32_t t,
                F&& arc) {
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      const uint32_t v = node[grid.Index(r, c)];
      if (v == kNone) continue;
      const bool left_free = grid.LeftLinked(r, c), below_free = grid.BelowLinked(r, c);
      // H start: c is H and its left neighbour is not H.  V start: c is V and
      // its lower neighbour is not V. A cell with neither neighbour pays one
      // start whatever its orientation: that unit of flow s->v->t is pushed
      // up front (a constant) instead of being found by the max-flow.
      if (!left_free && !below_free) continue;
      arc(v, left_free ? node[grid.Index(r, c - 1)] : t);
      arc(below_free ? node[grid.Index(r - 1, c)] : s, v);
    }
  }
}

}  // namespace

absl::StatusOr<RankPartition> MinCutPartitioner::Partition(const Grid& grid,
                                                           const StopToken& stop) const {
  if (grid.size() == 0) return absl::InvalidArgumentError("grid is empty");
  // Node ids: free cells in index order, then source and sink.
  std::vector<uint32_t> node(grid.size(), kNone);
  uint32_t n = 0;
  int64_t constant = 0;
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!grid.IsFree(r, c)) continue;
      node[grid.Index(r, c)] = n++;
      constant += !grid.LeftLinked(r, c) && !grid.BelowLinked(r, c);
    }
  }
  if (n == 0) return absl::InvalidArgumentError("grid has no free cell");
  const uint32_t s = n, t = n + 1, num_nodes = n + 2;

  // CSR layout built in place: every arc u->v (capacity 1) is stored with its
  // reverse v->u (capacity 0), as Boykov-Kolmogorov needs a reverse-edge map.
  std::vector<uint32_t> offset(num_nodes + 1, 0);
  ForEachArc(grid, node, s, t, [&](uint32_t u, uint32_t v) { ++offset[u + 1], ++offset[v + 1]; });
  for (uint32_t i = 0; i < num_nodes; ++i) offset[i + 1] += offset[i];
  const size_t m = offset[num_nodes];
  std::vector<std::pair<uint32_t, uint32_t>> edges(m);
  std::vector<int32_t> capacity(m);
  std::vector<uint32_t> reverse(m);
  {
    std::vector<uint32_t> next(offset.begin(), offset.end() - 1);
    ForEachArc(grid, node, s, t, [&](uint32_t u, uint32_t v) {
      const uint32_t p = next[u]++, q = next[v]++;
      edges[p] = {u, v}, capacity[p] = 1, reverse[p] = q;
      edges[q] = {v, u}, capacity[q] = 0, reverse[q] = p;
    });
  }
  if (stop.ShouldStop()) return absl::DeadlineExceededError("partition stopped before max-flow");

  // The arcs with capacity 1 run west, north, out of s or into t: a DAG. One
  // depth-first pass with current-arc pointers and dead-end pruning pushes a
  // blocking flow along them in O(arcs). Boykov-Kolmogorov then only finishes
  // the residual graph, where its search trees stay small; on open areas,
  // whose augmenting paths cross the whole map, this is what keeps it fast.
  int64_t preflow = 0;
  if (greedy_preflow_) {
    // Dead nodes cannot reach t through unsaturated forward arcs; that stays
    // true as capacities only fall, so one pass yields a blocking flow.
    std::vector<uint8_t> forward(capacity.begin(), capacity.end());
    std::vector<uint32_t> cur(offset.begin(), offset.end() - 1);
    std::vector<uint8_t> dead(num_nodes, 0);
    std::vector<uint32_t> path_nodes = {s}, path_arcs;
    while (!path_nodes.empty()) {
      const uint32_t u = path_nodes.back();
      if (u == t) {
        for (uint32_t p : path_arcs) --capacity[p], ++capacity[reverse[p]];
        ++preflow;
        path_nodes.resize(1);
        path_arcs.clear();
        continue;
      }
      bool advanced = false;
      for (; cur[u] < offset[u + 1]; ++cur[u]) {
        const uint32_t p = cur[u], v = edges[p].second;
        if (forward[p] && capacity[p] > 0 && !dead[v]) {
          path_nodes.push_back(v);
          path_arcs.push_back(p);
          advanced = true;
          break;
        }
      }
      if (!advanced) {
        dead[u] = 1;
        path_nodes.pop_back();
        if (!path_arcs.empty()) path_arcs.pop_back();
      }
    }
  }

  CsrGraph g(boost::edges_are_sorted, edges.begin(), edges.end(), num_nodes);
  std::vector<EdgeDesc> reverse_edge(m);
  for (size_t p = 0; p < m; ++p) reverse_edge[p] = EdgeDesc(edges[reverse[p]].first, reverse[p]);
  edges = {};
  reverse = {};

  auto edge_index = boost::get(boost::edge_index, g);
  auto vertex_index = boost::get(boost::vertex_index, g);
  std::vector<int32_t> residual(m, 0);
  int64_t flow = 0;
  std::vector<uint8_t> orientation(grid.size(), 1);
  {
    std::vector<EdgeDesc> predecessor(num_nodes);
    std::vector<boost::default_color_type> color(num_nodes);
    std::vector<int64_t> distance(num_nodes, 0);
    flow = boost::boykov_kolmogorov_max_flow(
        g, boost::make_iterator_property_map(capacity.begin(), edge_index),
        boost::make_iterator_property_map(residual.begin(), edge_index),
        boost::make_iterator_property_map(reverse_edge.begin(), edge_index),
        boost::make_iterator_property_map(predecessor.begin(), vertex_index),
        boost::make_iterator_property_map(color.begin(), vertex_index),
        boost::make_iterator_property_map(distance.begin(), vertex_index), vertex_index, s, t);
    // Source side (black: reachable from s in the residual graph) = horizontal.
    for (int64_t i = 0; i < grid.size(); ++i) {
      if (node[i] != kNone && color[node[i]] == boost::black_color) orientation[i] = 0;
    }
  }
  // The cut value is the LP optimum.
  return CheckedPartition(grid, std::move(orientation), preflow + flow + constant, "min-cut");
}

}  // namespace covplan
