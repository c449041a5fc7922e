#include "planner/partition/mincut_partitioner.h"

#include <cstdint>
#include <utility>
#include <vector>

#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/property_map/property_map.hpp>
#include <boost/range/iterator_range.hpp>

#include "absl/strings/str_format.h"

namespace covplan {
namespace {

using CsrGraph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property,
                                                    boost::no_property, boost::no_property,
                                                    uint32_t, uint32_t>;
using Traits = boost::graph_traits<CsrGraph>;

// Arcs of the cut graph before CSR layout. Every arc is stored with its
// zero-capacity reverse, as Boykov-Kolmogorov needs a reverse-edge map.
struct ArcList {
  std::vector<uint32_t> from, to;
  std::vector<int32_t> cap;
  void Add(uint32_t u, uint32_t v, int32_t c) {
    from.push_back(u), to.push_back(v), cap.push_back(c);
    from.push_back(v), to.push_back(u), cap.push_back(0);
  }
};

}  // namespace

absl::StatusOr<RankPartition> MinCutPartitioner::Partition(const Grid& grid,
                                                           const StopToken& stop) const {
  if (grid.size() == 0) return absl::InvalidArgumentError("grid is empty");
  // Node ids: free cells in index order, then source and sink.
  std::vector<uint32_t> node(grid.size(), UINT32_MAX);
  uint32_t n = 0;
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (grid.free_flags()[i]) node[i] = n++;
  }
  if (n == 0) return absl::InvalidArgumentError("grid has no free cell");
  const uint32_t s = n, t = n + 1;

  ArcList arcs;
  arcs.from.reserve(8ull * n);
  arcs.to.reserve(8ull * n);
  arcs.cap.reserve(8ull * n);
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!grid.IsFree(r, c)) continue;
      const uint32_t v = node[grid.Index(r, c)];
      // Horizontal start: c is H and its left neighbour is not H.
      if (grid.IsFree(r, c - 1)) {
        arcs.Add(v, node[grid.Index(r, c - 1)], 1);
      } else {
        arcs.Add(v, t, 1);
      }
      // Vertical start: c is V and its lower neighbour is not V.
      if (grid.IsFree(r - 1, c)) {
        arcs.Add(node[grid.Index(r - 1, c)], v, 1);
      } else {
        arcs.Add(s, v, 1);
      }
    }
  }
  if (stop.ShouldStop()) return absl::DeadlineExceededError("partition stopped before max-flow");

  // Counting sort by source so the CSR edge index equals our position.
  const uint32_t num_nodes = n + 2;
  const size_t m = arcs.from.size();
  std::vector<uint32_t> offset(num_nodes + 1, 0);
  for (uint32_t u : arcs.from) ++offset[u + 1];
  for (uint32_t i = 0; i < num_nodes; ++i) offset[i + 1] += offset[i];
  std::vector<uint32_t> pos(m);
  {
    std::vector<uint32_t> next(offset.begin(), offset.end() - 1);
    for (size_t k = 0; k < m; ++k) pos[k] = next[arcs.from[k]]++;
  }
  std::vector<std::pair<uint32_t, uint32_t>> sorted_edges(m);
  std::vector<int32_t> capacity(m);
  std::vector<uint32_t> reverse(m);
  for (size_t k = 0; k < m; ++k) {
    sorted_edges[pos[k]] = {arcs.from[k], arcs.to[k]};
    capacity[pos[k]] = arcs.cap[k];
    reverse[pos[k]] = pos[k ^ 1];  // arcs are added in (forward, reverse) pairs
  }
  arcs = ArcList();  // release memory before the flow

  CsrGraph g(boost::edges_are_sorted, sorted_edges.begin(), sorted_edges.end(), num_nodes);
  sorted_edges.clear();
  sorted_edges.shrink_to_fit();

  auto edge_index = boost::get(boost::edge_index, g);
  auto vertex_index = boost::get(boost::vertex_index, g);
  std::vector<Traits::edge_descriptor> edge_of(m);
  for (auto e : boost::make_iterator_range(boost::edges(g))) edge_of[e.idx] = e;
  std::vector<Traits::edge_descriptor> reverse_edge(m);
  for (size_t k = 0; k < m; ++k) reverse_edge[k] = edge_of[reverse[k]];

  std::vector<int32_t> residual(m, 0);
  std::vector<Traits::edge_descriptor> predecessor(num_nodes);
  std::vector<boost::default_color_type> color(num_nodes);
  std::vector<int64_t> distance(num_nodes, 0);

  const int32_t flow = boost::boykov_kolmogorov_max_flow(
      g, boost::make_iterator_property_map(capacity.begin(), edge_index),
      boost::make_iterator_property_map(residual.begin(), edge_index),
      boost::make_iterator_property_map(reverse_edge.begin(), edge_index),
      boost::make_iterator_property_map(predecessor.begin(), vertex_index),
      boost::make_iterator_property_map(color.begin(), vertex_index),
      boost::make_iterator_property_map(distance.begin(), vertex_index), vertex_index, s, t);

  // Source side (black: reachable from s in the residual graph) = horizontal.
  RankPartition result;
  result.orientation.assign(grid.size(), 1);
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (node[i] != UINT32_MAX && color[node[i]] == boost::black_color) result.orientation[i] = 0;
  }
  result.ranks = RanksFromOrientation(grid, result.orientation);
  result.objective = flow;
  if (static_cast<int64_t>(result.ranks.size()) != flow) {
    return absl::InternalError(absl::StrFormat(
        "min-cut value %d disagrees with %d ranks from the cut", flow, result.ranks.size()));
  }
  return result;
}

}  // namespace covplan
