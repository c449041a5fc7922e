#include "planner/tour/endpoint_graph.h"

#include <algorithm>
#include <atomic>
#include <thread>

#include "planner/tour/grid_paths.h"

namespace covplan {
int EndpointGraph::component(CellIndex c) const {
  if (c.row < 0 || c.col < 0 || c.row >= rows_ || c.col >= cols_) return -1;
  return comp_[c.row * cols_ + c.col];
}

absl::StatusOr<std::shared_ptr<const EndpointGraph>> EndpointGraph::Build(
    const Grid& grid, std::vector<CellIndex> endpoints, const Options& options,
    const StopToken& stop, int num_threads) {
  auto g = std::make_shared<EndpointGraph>();
  const int count = static_cast<int>(endpoints.size());
  for (const CellIndex& c : endpoints) {
    if (!grid.IsFree(c))
      return absl::InvalidArgumentError("transition endpoint lies on a blocked cell");
  }
  g->rows_ = grid.rows();
  g->cols_ = grid.cols();
  g->endpoints_ = std::move(endpoints);
  int32_t num_components = 0;
  g->comp_ = FreeComponents(grid, &num_components);
  g->endpoint_component_.resize(count);
  g->head_.assign(grid.size(), -1);
  g->next_.assign(count, -1);
  for (int e = count - 1; e >= 0; --e) {
    const int64_t i = grid.Index(g->endpoints_[e].row, g->endpoints_[e].col);
    g->endpoint_component_[e] = g->comp_[i];
    g->next_[e] = g->head_[i];
    g->head_[i] = e;
  }
  const int k = std::max(1, options.neighbours);
  int64_t max_settled = options.max_settled;
  if (max_settled <= 0) {
    max_settled = std::max<int64_t>(20000, 64 * grid.CountFree() / std::max(1, count));
  }

  // Forward lists: the k nearest endpoints met by each endpoint's search.
  // Endpoints sharing a cell share one search.
  // Per endpoint: (candidate, its intermediate corners from the endpoint).
  struct Found {
    int32_t endpoint;
    float length;
    std::vector<CellIndex> corners;
  };
  std::vector<std::vector<Found>> forward(count);
  std::atomic<int> next{0};
  std::atomic<bool> stopped{false};
  auto worker = [&] {
    AnyAngleSearch search(grid);
    std::vector<EndpointCandidate> found;
    for (int e = next++; e < count && !stopped; e = next++) {
      const int64_t cell = grid.Index(g->endpoints_[e].row, g->endpoints_[e].col);
      if (g->head_[cell] != e) continue;  // the first endpoint at the cell searches for all
      // Every endpoint at this cell needs k others besides itself and its
      // partner: collect k + (endpoints here) + 1 to be safe, trim later.
      int here = 0;
      g->ForEachEndpointAt(cell, [&](int) { ++here; });
      const size_t want = static_cast<size_t>(k + 2 * here);
      found.clear();
      const bool ok = search.Explore(g->endpoints_[e], max_settled, stop, [&](int64_t s, float d) {
        g->ForEachEndpointAt(s, [&](int f) { found.push_back({f, d, 0, 0}); });
        return found.size() < want;
      });
      if (!ok || stop.ShouldStop()) {
        stopped = true;
        return;
      }
      g->ForEachEndpointAt(cell, [&](int a) {
        std::vector<Found>& list = forward[a];
        for (const EndpointCandidate& c : found) {
          if (c.endpoint == a || c.endpoint == (a ^ 1)) continue;
          if (static_cast<int>(list.size()) >= k) break;
          std::vector<CellIndex> path = search.PathTo(g->endpoints_[c.endpoint]);
          std::vector<CellIndex> corners;
          if (path.size() > 2) corners.assign(path.begin() + 1, path.end() - 1);
          list.push_back({c.endpoint, c.length_cells, std::move(corners)});
        }
      });
    }
  };
  const int threads = std::max(1, std::min(num_threads, count));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (stopped || stop.ShouldStop()) {
    return absl::DeadlineExceededError("stopped while computing transition candidates");
  }
  // Symmetrise: b in a's list whenever a is in b's (the path reversed).
  std::vector<std::vector<Found>> lists(count);
  for (int a = 0; a < count; ++a) {
    for (const Found& f : forward[a]) {
      lists[a].push_back(f);
      Found back{a, f.length, std::vector<CellIndex>(f.corners.rbegin(), f.corners.rend())};
      lists[f.endpoint].push_back(std::move(back));
    }
  }
  forward.clear();
  g->offsets_.assign(count + 1, 0);
  for (int a = 0; a < count; ++a) {
    std::vector<Found>& list = lists[a];
    std::stable_sort(list.begin(), list.end(), [](const Found& x, const Found& y) {
      return x.length < y.length || (x.length == y.length && x.endpoint < y.endpoint);
    });
    // Each endpoint once (the forward entry, found first, wins).
    std::vector<Found> unique;
    for (Found& f : list) {
      if (std::none_of(unique.begin(), unique.end(),
                       [&](const Found& u) { return u.endpoint == f.endpoint; })) {
        unique.push_back(std::move(f));
      }
    }
    for (const Found& f : unique) {
      g->cands_.push_back({f.endpoint, f.length, static_cast<uint32_t>(g->corners_.size()),
                           static_cast<uint32_t>(f.corners.size())});
      g->corners_.insert(g->corners_.end(), f.corners.begin(), f.corners.end());
    }
    g->offsets_[a + 1] = static_cast<int64_t>(g->cands_.size());
    std::vector<Found>().swap(list);
  }
  return std::shared_ptr<const EndpointGraph>(std::move(g));
}

void EndpointGraph::AppendPath(int e, const EndpointCandidate& c,
                               std::vector<CellIndex>* out) const {
  out->push_back(endpoints_[e]);
  for (uint32_t i = 0; i < c.corner_count; ++i) out->push_back(corners_[c.corner_offset + i]);
  if (endpoints_[c.endpoint] != endpoints_[e]) out->push_back(endpoints_[c.endpoint]);
}

size_t EndpointGraph::MemoryBytes() const {
  return sizeof(*this) + endpoints_.capacity() * sizeof(CellIndex) +
         comp_.capacity() * sizeof(int32_t) + endpoint_component_.capacity() * sizeof(int32_t) +
         head_.capacity() * sizeof(int32_t) + next_.capacity() * sizeof(int32_t) +
         offsets_.capacity() * sizeof(int64_t) + cands_.capacity() * sizeof(EndpointCandidate) +
         corners_.capacity() * sizeof(CellIndex);
}

int64_t EndpointGraph::EstimateBytes(int64_t cells, int64_t endpoints, int neighbours,
                                     int num_threads) {
  // Forward and symmetrised lists while building (each entry a small vector
  // of ~8 corners), the final CSR and its corners.
  const int64_t per_candidate = sizeof(EndpointCandidate) + 48 + 8 * sizeof(CellIndex);
  const int64_t per_endpoint = sizeof(CellIndex) + 2 * sizeof(int32_t) + sizeof(int64_t) +
                               4 * static_cast<int64_t>(neighbours) * per_candidate;
  return cells * 3 *
             static_cast<int64_t>(sizeof(int32_t)) +  // components, cell -> endpoint, labelling
         std::max(1, num_threads) * cells * AnyAngleSearch::kBytesPerCell +
         endpoints * per_endpoint;
}

}  // namespace covplan
