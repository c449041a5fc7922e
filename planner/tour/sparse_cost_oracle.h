// The cost oracle of the sparse rank tour (planner/tour/sparse_tour.h): the
// drive time of a transition between two tour nodes without any dense
// matrix. Nodes 0..2n-1 are the rank endpoints (2k = ranks[k].first,
// 2k + 1 = ranks[k].last), S = 2n the start pose and E = 2n + 1 the end pose
// (the start again when there is none). A transition x -> y costs what
// RankTourCost charges: the time model along the any-angle path, turning
// from x's rank heading and onto y's.
//
// Three prices, cheapest first: LowerCost (a straight line plus its turns),
// ProbeCost (a search capped at a few expansions, whose open frontier bounds
// the distance) and ExactCost (the candidate lists, the cache, else a full
// search). Exact and probed costs are cached per request, keyed by the
// unordered pair (paths are symmetric); a completed search also caches the
// exact cost to every endpoint it settled on the way.
//
//   SparseCostOracle costs(drive, ranks, graph, robot, max_cached);
//   if (!costs.Prepare(start, start_cell, end, end_cell, stop)) ...;
//   AnyAngleSearch search(drive);  // one per thread
//   double c = costs.ExactCost(x, y, &search, stop);
//
// Thread-safety: after Prepare, every method may be called from many
// threads at once (the cache is sharded under mutexes), each with its own
// AnyAngleSearch.
#ifndef COVPLAN_PLANNER_TOUR_SPARSE_COST_ORACLE_H_
#define COVPLAN_PLANNER_TOUR_SPARSE_COST_ORACLE_H_

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/types/span.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"
#include "planner/tour/endpoint_graph.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/rank_tour.h"
#include "planner/tour/robot_model.h"

namespace covplan {
namespace sparse_internal {

class SparseCostOracle {
 public:
  SparseCostOracle(const Grid& grid, const std::vector<Rank>& ranks, const EndpointGraph& graph,
                   const RobotModel& robot, int64_t max_cached);

  // Poses, the candidates of S and E (nearest endpoints of a bounded
  // search) and the drive time of every candidate transition. False when
  // `stop` fired.
  bool Prepare(const Pose2& start, CellIndex start_cell, const Pose2& end, CellIndex end_cell,
               const StopToken& stop);

  int n() const { return n_; }
  int S() const { return 2 * n_; }
  int E() const { return 2 * n_ + 1; }
  CellIndex cell(int node) const { return cells_[node]; }
  const Grid& grid() const { return grid_; }
  absl::Span<const EndpointCandidate> candidates(int node) const {
    if (node < 2 * n_) return graph_.candidates(node);
    return absl::MakeConstSpan(pose_cands_[node - S()]);
  }
  // Drive time of the i-th candidate of `node` (node -> it; for E: it -> E).
  double CandidateCost(int node, size_t i) const {
    if (node < 2 * n_) return cand_costs_[candidate_base(node) + i];
    return pose_costs_[node - S()][i];
  }
  // True when ExactCost(x, y) needs no search (a candidate pair).
  bool Known(int x, int y) const {
    if (cells_[x] == cells_[y]) return true;
    for (const EndpointCandidate& c : candidates(x)) {
      if (c.endpoint == y) return true;
    }
    return false;
  }

  // The time of driving a straight line of `cells` cells.
  double StraightCost(float cells) const { return robot_.StraightTime(cells * grid_.cell_size()); }
  // Lower bound of the drive time x -> y.
  double LowerCost(int x, int y) const {
    return BoundCost(x, y, graph_.LowerBoundCells(cells_[x], cells_[y]));
  }
  // Exact drive time x -> y: candidate lists, the cache, then a search.
  // Infinity (not cached) if `stop` fires during the search.
  double ExactCost(int x, int y, AnyAngleSearch* search, const StopToken& stop);
  // A cheap, tighter lower bound of ExactCost(x, y) (or the exact cost): a
  // search capped at kProbeExpansions, whose open frontier bounds the
  // distance when it does not reach y. Pairs across walls, whose Euclidean
  // bound is loose, are mostly rejected here without a full search.
  double ProbeCost(int x, int y, AnyAngleSearch* search);

  int64_t probes() const { return probes_.load(); }
  int64_t harvested() const { return harvested_.load(); }
  int64_t searches() const { return searches_.load(); }

 private:
  static constexpr int kStartNeighbours = 16;
  static constexpr int64_t kProbeExpansions = 1500;
  struct Cached {
    double cost;
    bool exact;  // else a lower bound from a capped search
  };
  struct Shard {
    std::mutex mu;
    absl::flat_hash_map<uint64_t, Cached> map;
  };

  // Heading of the rank driven into endpoint y (entry) / out of endpoint x.
  double EntryHeading(int y) const { return RankHeading(ranks_[y / 2], y % 2 == 0); }
  double ExitHeading(int x) const { return x == S() ? start_theta_ : EntryHeading(x ^ 1); }
  // The time model on a path x -> y given as cells (x's cell .. y's cell):
  // exactly RankTourCost's (poses at the ends of S and E legs).
  double PathCost(int x, int y, const std::vector<CellIndex>& cells) const;
  // Lower bound of the drive time x -> y: a straight segment of `len` cells
  // plus the turns onto and off the straight line x -> y.
  double BoundCost(int x, int y, float len) const;
  // After a completed search from x's cell (aimed at y): every other rank
  // endpoint z it closed has its final path, so (x, z) gets its exact cost
  // now instead of a search of its own later.
  void Harvest(int x, int y, const AnyAngleSearch& search);
  // The cache key of the pair: endpoint pairs are symmetric (the path
  // reversed, headings flipped).
  uint64_t PairKey(int x, int y) const {
    return static_cast<uint64_t>(std::min(x, y)) * (2 * n_ + 2) + std::max(x, y);
  }
  Shard& ShardOf(uint64_t key) { return shards_[(key * 0x9E3779B97F4A7C15ULL) >> 58]; }
  // The exact cost x -> y once `search` has reached y's cell: cached, and
  // the other endpoints the search closed harvested.
  double PriceSearched(int x, int y, uint64_t key, Shard& shard, const AnyAngleSearch& search);
  void Store(Shard& shard, uint64_t key, Cached value);
  size_t candidate_base(int e) const {
    return static_cast<size_t>(graph_.candidates(e).data() - graph_.candidates(0).data());
  }

  const Grid& grid_;
  const std::vector<Rank>& ranks_;
  const EndpointGraph& graph_;
  RobotModel robot_;
  int64_t max_cached_;
  int n_ = 0;
  double turn_rate_ = 1.0;
  double start_theta_ = 0.0;
  std::vector<CellIndex> cells_;
  std::vector<Point2> pts_;
  std::vector<EndpointCandidate> pose_cands_[2];
  std::vector<double> pose_costs_[2];
  std::vector<double> cand_costs_;  // parallel to the graph's candidates
  Shard shards_[64];
  std::atomic<int64_t> cached_{0}, searches_{0}, probes_{0}, harvested_{0};
  static thread_local std::vector<CellIndex> harvest_cells_;
  StopToken never_;
};

}  // namespace sparse_internal
}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_SPARSE_COST_ORACLE_H_
