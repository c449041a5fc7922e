#include "planner/tour/transitions.h"

#include <algorithm>
#include <atomic>
#include <thread>
#include <unordered_map>

#include "planner/tour/grid_paths.h"

namespace covplan {

absl::StatusOr<std::shared_ptr<const TransitionTable>> TransitionTable::Build(
    const Grid& grid, const std::vector<Rank>& ranks, const StopToken& stop, int num_threads) {
  std::vector<CellIndex> endpoints;
  endpoints.reserve(ranks.size() * 2);
  for (const Rank& r : ranks) {
    endpoints.push_back(r.first);
    endpoints.push_back(r.last);
  }
  return BuildForEndpoints(grid, std::move(endpoints), stop, num_threads);
}

absl::StatusOr<std::shared_ptr<const TransitionTable>> TransitionTable::BuildForEndpoints(
    const Grid& grid, std::vector<CellIndex> endpoints, const StopToken& stop, int num_threads) {
  auto table = std::make_shared<TransitionTable>();
  const int e_count = static_cast<int>(endpoints.size());
  table->num_endpoints_ = e_count;
  for (const CellIndex& c : endpoints) {
    if (!grid.IsFree(c))
      return absl::InvalidArgumentError("transition endpoint lies on a blocked cell");
  }
  table->endpoints_ = std::move(endpoints);
  table->pairs_.assign(static_cast<size_t>(e_count) * e_count, PairInfo{});
  table->corners_.assign(e_count, {});

  // Endpoints sharing a cell (single-cell ranks) share one search.
  std::unordered_map<int64_t, std::vector<int>> by_cell;
  for (int e = 0; e < e_count; ++e) {
    const CellIndex c = table->endpoints_[e];
    by_cell[grid.Index(c.row, c.col)].push_back(e);
  }
  std::vector<std::vector<int>> groups;
  groups.reserve(by_cell.size());
  for (auto& [cell, members] : by_cell) groups.push_back(std::move(members));
  std::sort(groups.begin(), groups.end());

  std::atomic<size_t> next{0};
  std::atomic<bool> stopped{false};
  auto worker = [&] {
    AnyAngleSearch search(grid);
    std::vector<CellIndex> path;
    for (size_t g = next++; g < groups.size() && !stopped; g = next++) {
      const int source = groups[g][0];
      // Small grids finish a search within the search's own polling interval:
      // poll before each one too, so a deadline stops the table promptly.
      if (stop.ShouldStop() || !search.Run(table->endpoints_[source], stop)) {
        stopped = true;
        return;
      }
      // Paths from this cell, stored once and shared by its endpoints.
      std::vector<CellIndex>& corners = table->corners_[source];
      std::vector<PairInfo> row(e_count);
      for (int b = 0; b < e_count; ++b) {
        path = search.PathTo(table->endpoints_[b]);
        if (path.empty()) continue;
        row[b].length = search.DistanceCells(table->endpoints_[b]);
        row[b].offset = static_cast<uint32_t>(corners.size());
        row[b].count = static_cast<uint32_t>(path.size() >= 2 ? path.size() - 2 : 0);
        for (size_t k = 1; k + 1 < path.size(); ++k) corners.push_back(path[k]);
      }
      corners.shrink_to_fit();
      for (int a : groups[g]) {
        std::copy(row.begin(), row.end(), table->pairs_.begin() + table->Pair(a, 0));
      }
    }
  };
  const int threads = std::max(1, std::min<int>(num_threads, static_cast<int>(groups.size())));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (stopped || stop.ShouldStop()) {
    return absl::DeadlineExceededError("stopped while computing transition paths");
  }
  // Endpoints that share a cell point at the group source's corner list.
  table->alias_.assign(e_count, -1);
  for (const auto& members : groups) {
    for (int a : members) table->alias_[a] = members[0];
  }
  return std::shared_ptr<const TransitionTable>(std::move(table));
}

void TransitionTable::AppendPath(int a, int b, std::vector<CellIndex>* out) const {
  const PairInfo& p = pairs_[Pair(a, b)];
  if (p.length < 0.0f) return;
  out->push_back(endpoints_[a]);
  const std::vector<CellIndex>& corners = corners_[alias_[a]];
  for (uint32_t k = 0; k < p.count; ++k) out->push_back(corners[p.offset + k]);
  if (endpoints_[b] != endpoints_[a]) out->push_back(endpoints_[b]);
}

size_t TransitionTable::MemoryBytes() const {
  size_t bytes = sizeof(*this) + pairs_.capacity() * sizeof(PairInfo) +
                 endpoints_.capacity() * sizeof(CellIndex) + alias_.capacity() * sizeof(int);
  for (const auto& c : corners_) bytes += sizeof(c) + c.capacity() * sizeof(CellIndex);
  return bytes;
}

}  // namespace covplan
