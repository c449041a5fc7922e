#include "planner/tour/sparse_cost_oracle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "planner/tour/path_timing.h"

namespace covplan {
namespace sparse_internal {

thread_local std::vector<CellIndex> SparseCostOracle::harvest_cells_;

SparseCostOracle::SparseCostOracle(const Grid& grid, const std::vector<Rank>& ranks,
                                   const EndpointGraph& graph, const RobotModel& robot,
                                   int64_t max_cached)
    : grid_(grid), ranks_(ranks), graph_(graph), robot_(robot), max_cached_(max_cached) {
  n_ = static_cast<int>(ranks.size());
  cells_.resize(2 * n_ + 2);
  pts_.resize(2 * n_ + 2);
  for (int e = 0; e < 2 * n_; ++e) {
    cells_[e] = graph.endpoint(e);
    pts_[e] = grid.CellCenter(cells_[e]);
  }
  turn_rate_ = robot.turn_rate_deg_s * M_PI / 180.0;
}

bool SparseCostOracle::Prepare(const Pose2& start, CellIndex start_cell, const Pose2& end,
                               CellIndex end_cell, const StopToken& stop) {
  start_theta_ = start.theta;
  cells_[S()] = start_cell;
  cells_[E()] = end_cell;
  pts_[S()] = {start.x, start.y};
  pts_[E()] = {end.x, end.y};
  AnyAngleSearch search(grid_);
  std::vector<CellIndex> cells;
  for (int node : {S(), E()}) {
    std::vector<EndpointCandidate>& list = pose_cands_[node - S()];
    std::vector<double>& costs = pose_costs_[node - S()];
    std::vector<std::pair<int, float>> found;
    if (!search.Explore(cells_[node], std::max<int64_t>(20000, grid_.size() / 16), stop,
                        [&](int64_t cell, float d) {
                          graph_.ForEachEndpointAt(cell, [&](int e) { found.push_back({e, d}); });
                          return found.size() < static_cast<size_t>(kStartNeighbours);
                        })) {
      return false;
    }
    for (const auto& [e, d] : found) {
      list.push_back({e, d, 0, 0});
      cells = search.PathTo(cells_[e]);  // node .. e
      if (node == E()) std::reverse(cells.begin(), cells.end());
      costs.push_back(node == S() ? PathCost(S(), e, cells) : PathCost(e, E(), cells));
    }
  }
  for (int e = 0; e < 2 * n_; ++e) {
    for (const EndpointCandidate& c : graph_.candidates(e)) {
      cells.clear();
      graph_.AppendPath(e, c, &cells);
      cand_costs_.push_back(PathCost(e, c.endpoint, cells));
    }
  }
  return true;
}

double SparseCostOracle::PathCost(int x, int y, const std::vector<CellIndex>& cells) const {
  thread_local std::vector<Point2> pts;
  pts.clear();
  if (x == S()) pts.push_back(pts_[S()]);
  for (const CellIndex& c : cells) pts.push_back(grid_.CellCenter(c));
  if (y == E()) pts.push_back(pts_[E()]);
  std::optional<double> out;
  if (y != E()) out = EntryHeading(y);
  return TimePolyline(robot_, pts, ExitHeading(x), out).time_s;
}

double SparseCostOracle::BoundCost(int x, int y, float len) const {
  if (!(len < kNoPath)) return std::numeric_limits<double>::infinity();
  double t = robot_.StraightTime(len * grid_.cell_size());
  const double h0 = ExitHeading(x);
  const bool final_turn = y != E();
  const double dx = pts_[y].x - pts_[x].x, dy = pts_[y].y - pts_[x].y;
  if (dx * dx + dy * dy < 1e-18) {
    if (final_turn) t += HeadingChange(h0, EntryHeading(y)) / turn_rate_;
    return t;
  }
  const double th = std::atan2(dy, dx);
  t += HeadingChange(h0, th) / turn_rate_;
  if (final_turn) t += HeadingChange(th, EntryHeading(y)) / turn_rate_;
  return t;
}

double SparseCostOracle::ExactCost(int x, int y, AnyAngleSearch* search, const StopToken& stop) {
  const absl::Span<const EndpointCandidate> cx = candidates(x);
  for (size_t i = 0; i < cx.size(); ++i) {
    if (cx[i].endpoint == y) return CandidateCost(x, i);
  }
  if (y == E()) {
    const absl::Span<const EndpointCandidate> cy = candidates(y);
    for (size_t i = 0; i < cy.size(); ++i) {
      if (cy[i].endpoint == x) return CandidateCost(y, i);
    }
  }
  const CellIndex a = cells_[x], b = cells_[y];
  if (graph_.component(a) != graph_.component(b) || graph_.component(a) < 0) {
    return std::numeric_limits<double>::infinity();
  }
  if (a == b) return PathCost(x, y, {a});
  const uint64_t key = PairKey(x, y);
  Shard& shard = ShardOf(key);
  {
    std::lock_guard<std::mutex> lock(shard.mu);
    auto it = shard.map.find(key);
    if (it != shard.map.end() && it->second.exact) return it->second.cost;
  }
  if (!search->RunTo(a, b, stop)) return std::numeric_limits<double>::infinity();
  return PriceSearched(x, y, key, shard, *search);
}

double SparseCostOracle::ProbeCost(int x, int y, AnyAngleSearch* search) {
  if (Known(x, y)) return ExactCost(x, y, search, never_);
  const CellIndex a = cells_[x], b = cells_[y];
  if (graph_.component(a) != graph_.component(b) || graph_.component(a) < 0) {
    return std::numeric_limits<double>::infinity();
  }
  const uint64_t key = PairKey(x, y);
  Shard& shard = ShardOf(key);
  {
    std::lock_guard<std::mutex> lock(shard.mu);
    auto it = shard.map.find(key);
    if (it != shard.map.end()) return it->second.cost;
  }
  float bound = 0.0f;
  probes_.fetch_add(1, std::memory_order_relaxed);
  if (!search->RunTo(a, b, never_, kProbeExpansions, &bound)) {
    const double c = BoundCost(x, y, bound);
    Store(shard, key, {c, false});
    return c;
  }
  return PriceSearched(x, y, key, shard, *search);
}

// About half the searches of a run are spared this way (measured in
// docs/benchmarks.md §14); only while the cache is less than half full, so
// harvests never crowd out the pairs searched for.
void SparseCostOracle::Harvest(int x, int y, const AnyAngleSearch& search) {
  if (x >= 2 * n_ || cached_.load(std::memory_order_relaxed) >= max_cached_ / 2) return;
  search.ForEachClosed([&](int64_t cell) {
    graph_.ForEachEndpointAt(cell, [&](int z) {
      if (z == x || z == y || cells_[z] == cells_[x] || Known(x, z)) return;
      const uint64_t key = PairKey(x, z);
      Shard& shard = ShardOf(key);
      {
        std::lock_guard<std::mutex> lock(shard.mu);
        auto it = shard.map.find(key);
        if (it != shard.map.end() && it->second.exact) return;
      }
      harvest_cells_ = search.PathTo(cells_[z]);
      if (harvest_cells_.empty()) return;
      Store(shard, key, {PathCost(x, z, harvest_cells_), true});
      harvested_.fetch_add(1, std::memory_order_relaxed);
    });
  });
}

double SparseCostOracle::PriceSearched(int x, int y, uint64_t key, Shard& shard,
                                       const AnyAngleSearch& search) {
  const std::vector<CellIndex> cells = search.PathTo(cells_[y]);
  const double c = cells.empty() ? std::numeric_limits<double>::infinity() : PathCost(x, y, cells);
  searches_.fetch_add(1, std::memory_order_relaxed);
  Store(shard, key, {c, true});
  Harvest(x, y, search);
  return c;
}

void SparseCostOracle::Store(Shard& shard, uint64_t key, Cached value) {
  std::lock_guard<std::mutex> lock(shard.mu);
  auto it = shard.map.find(key);
  if (it != shard.map.end()) {
    it->second = value;
  } else if (cached_.load(std::memory_order_relaxed) < max_cached_) {
    shard.map.emplace(key, value);
    cached_.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace sparse_internal
}  // namespace covplan
