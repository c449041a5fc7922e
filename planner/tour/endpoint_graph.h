// Sparse transitions between rank endpoints: the structure that replaces the
// all-pairs TransitionTable on large maps.
//
// Per endpoint, a bounded any-angle search (AnyAngleSearch::Explore: the
// same Lazy Theta* as the table's, cut short) settles cells in distance
// order and stops once it has met the `neighbours` nearest other endpoints
// (or settled `max_settled` cells): those become the endpoint's candidate
// list, with the exact any-angle path (length and corner cells) to each.
// Lists are symmetrised (b is a candidate of a when a is one of b; the path
// reversed). Any other pair gets a lower bound: the Euclidean distance when
// both cells lie in the same free component, kNoPath otherwise; its path
// comes on demand (AnyAngleSearch::RunTo). Searches run in parallel over
// `num_threads`. Memory is linear in the grid and the endpoints.
//
//   ASSIGN_OR_RETURN(auto graph, EndpointGraph::Build(grid, cells, {}, stop, 2));
//   for (const EndpointCandidate& c : graph->candidates(e)) graph->AppendPath(e, c, &cells);
//
// Thread-safety: EndpointGraph is immutable after Build.
#ifndef COVPLAN_PLANNER_TOUR_ENDPOINT_GRAPH_H_
#define COVPLAN_PLANNER_TOUR_ENDPOINT_GRAPH_H_

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"

namespace covplan {

inline constexpr float kNoPath = std::numeric_limits<float>::infinity();

// Straight-line distance between cell centres, in cells.
inline float EuclidCells(CellIndex a, CellIndex b) {
  const float dr = static_cast<float>(a.row - b.row), dc = static_cast<float>(a.col - b.col);
  return std::sqrt(dr * dr + dc * dc);
}

struct EndpointCandidate {
  int32_t endpoint;
  float length_cells;      // any-angle path length
  uint32_t corner_offset;  // intermediate corners, in order from the list's owner
  uint32_t corner_count;
};

class EndpointGraph {
 public:
  struct Options {
    int neighbours = 10;      // nearest endpoints kept per endpoint (before symmetrising)
    int64_t max_settled = 0;  // per search; 0 = max(20000, 64 * free cells / endpoints)
  };
  // Endpoints 2k and 2k + 1 are the two ends of rank k: e ^ 1 (e's own
  // rank) is never in e's list. InvalidArgument if an endpoint is blocked.
  static absl::StatusOr<std::shared_ptr<const EndpointGraph>> Build(
      const Grid& grid, std::vector<CellIndex> endpoints, const Options& options,
      const StopToken& stop, int num_threads);

  int num_endpoints() const { return static_cast<int>(endpoints_.size()); }
  CellIndex endpoint(int e) const { return endpoints_[e]; }
  int component(CellIndex c) const;  // -1 for blocked / outside
  int endpoint_component(int e) const { return endpoint_component_[e]; }
  // Sorted by length; never contains e itself or its partner.
  absl::Span<const EndpointCandidate> candidates(int e) const {
    return absl::MakeConstSpan(cands_.data() + offsets_[e], offsets_[e + 1] - offsets_[e]);
  }
  // Lower bound of the path length between two cells: Euclidean distance
  // in one component, kNoPath across components.
  float LowerBoundCells(CellIndex a, CellIndex b) const {
    if (component(a) != component(b) || component(a) < 0) return kNoPath;
    return EuclidCells(a, b);
  }
  // Appends e's cell, the corners of candidate `c` of e, and c's cell.
  void AppendPath(int e, const EndpointCandidate& c, std::vector<CellIndex>* out) const;
  // Endpoints whose cell is `cell_index` (several for single-cell ranks).
  template <typename F>
  void ForEachEndpointAt(int64_t cell_index, F&& f) const {
    for (int32_t e = head_[cell_index]; e >= 0; e = next_[e]) f(e);
  }

  size_t MemoryBytes() const;
  // Peak bytes of Build plus the graph for a grid of `cells` and `endpoints`.
  static int64_t EstimateBytes(int64_t cells, int64_t endpoints, int neighbours, int num_threads);

 private:
  int64_t cols_ = 0, rows_ = 0;
  std::vector<CellIndex> endpoints_;
  std::vector<int32_t> comp_;  // per cell
  std::vector<int32_t> endpoint_component_;
  std::vector<int32_t> head_, next_;  // cell -> endpoints at it
  std::vector<int64_t> offsets_;
  std::vector<EndpointCandidate> cands_;
  std::vector<CellIndex> corners_;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_ENDPOINT_GRAPH_H_
