#include "planner/tour/sparse_tour.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/gtsp/rng.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

constexpr double kEps = 1e-7;
constexpr int kStartNeighbours = 16;

double RankHeading(const Rank& r, bool forward) {
  if (r.orientation == Orientation::kHorizontal) return forward ? 0.0 : M_PI;
  return forward ? M_PI / 2 : -M_PI / 2;
}

// The read-mostly problem shared by all runs: nodes 0..2n-1 are the rank
// endpoints (2k = ranks[k].first, 2k + 1 = ranks[k].last), S = 2n the start,
// E = 2n + 1 the end (the start again when there is no end pose).
class Problem {
 public:
  Problem(const Grid& grid, const std::vector<Rank>& ranks, const EndpointGraph& graph,
          const RobotModel& robot, int64_t max_cached)
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

  // Poses, the candidates of S and E (nearest endpoints of a bounded
  // search) and the drive time of every candidate transition.
  bool Prepare(const Pose2& start, CellIndex start_cell, const Pose2& end, CellIndex end_cell,
               const StopToken& stop) {
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

  int n() const { return n_; }
  int S() const { return 2 * n_; }
  int E() const { return 2 * n_ + 1; }
  CellIndex cell(int node) const { return cells_[node]; }
  absl::Span<const EndpointCandidate> candidates(int node) const {
    if (node < 2 * n_) return graph_.candidates(node);
    return absl::MakeConstSpan(pose_cands_[node - S()]);
  }
  // Drive time of the i-th candidate of `node` (node -> it; for E: it -> E).
  double CandidateCost(int node, size_t i) const {
    if (node < 2 * n_) return cand_costs_[candidate_base(node) + i];
    return pose_costs_[node - S()][i];
  }
  // Heading of the rank driven into endpoint y (entry) / out of endpoint x.
  double EntryHeading(int y) const { return RankHeading(ranks_[y / 2], y % 2 == 0); }
  double ExitHeading(int x) const { return x == S() ? start_theta_ : EntryHeading(x ^ 1); }

  // The time model on a path x -> y given as cells (x's cell .. y's cell):
  // exactly RankTourCost's (poses at the ends of S and E legs).
  double PathCost(int x, int y, const std::vector<CellIndex>& cells) const {
    thread_local std::vector<Point2> pts;
    pts.clear();
    if (x == S()) pts.push_back(pts_[S()]);
    for (const CellIndex& c : cells) pts.push_back(grid_.CellCenter(c));
    if (y == E()) pts.push_back(pts_[E()]);
    std::optional<double> out;
    if (y != E()) out = EntryHeading(y);
    return TimePolyline(robot_, pts, ExitHeading(x), out).time_s;
  }
  // Lower bound of the drive time x -> y: a straight segment of `len` cells
  // plus the turns onto and off the straight line x -> y.
  double BoundCost(int x, int y, float len) const {
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
  double StraightCost(float cells) const { return robot_.StraightTime(cells * grid_.cell_size()); }
  double LowerCost(int x, int y) const {
    return BoundCost(x, y, graph_.LowerBoundCells(cells_[x], cells_[y]));
  }

  // Exact drive time x -> y: candidate lists, the cache, then a search.
  // Infinity (not cached) if `stop` fires during the search.
  double ExactCost(int x, int y, AnyAngleSearch* search, const StopToken& stop) {
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

  // A cheap, tighter lower bound of ExactCost(x, y) (or the exact cost): a
  // search capped at kProbeExpansions, whose open frontier bounds the
  // distance when it does not reach y. Pairs across walls, whose Euclidean
  // bound is loose, are mostly rejected here without a full search.
  double ProbeCost(int x, int y, AnyAngleSearch* search) {
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
  // After a completed search from x's cell (aimed at y): every other rank
  // endpoint z it closed has its final path, so (x, z) gets its exact cost
  // now instead of a search of its own later (about half the searches of a
  // run, measured in docs/benchmarks.md §14). Only while the cache is less
  // than half full, so harvests never crowd out the pairs searched for.
  void Harvest(int x, int y, const AnyAngleSearch& search) {
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
  int64_t probes() const { return probes_.load(); }
  int64_t harvested() const { return harvested_.load(); }
  int64_t searches() const { return searches_.load(); }
  const Grid& grid() const { return grid_; }
  // True when ExactCost(x, y) needs no search (a candidate pair).
  bool Known(int x, int y) const {
    if (cells_[x] == cells_[y]) return true;
    for (const EndpointCandidate& c : candidates(x)) {
      if (c.endpoint == y) return true;
    }
    return false;
  }

 private:
  static constexpr int64_t kProbeExpansions = 1500;
  struct Cached {
    double cost;
    bool exact;  // else a lower bound from a capped search
  };
  struct Shard {
    std::mutex mu;
    absl::flat_hash_map<uint64_t, Cached> map;
  };
  // The cache key of the pair: endpoint pairs are symmetric (the path
  // reversed, headings flipped).
  uint64_t PairKey(int x, int y) const {
    return static_cast<uint64_t>(std::min(x, y)) * (2 * n_ + 2) + std::max(x, y);
  }
  Shard& ShardOf(uint64_t key) { return shards_[(key * 0x9E3779B97F4A7C15ULL) >> 58]; }
  // The exact cost x -> y once `search` has reached y's cell: cached, and
  // the other endpoints the search closed harvested.
  double PriceSearched(int x, int y, uint64_t key, Shard& shard, const AnyAngleSearch& search) {
    const std::vector<CellIndex> cells = search.PathTo(cells_[y]);
    const double c =
        cells.empty() ? std::numeric_limits<double>::infinity() : PathCost(x, y, cells);
    searches_.fetch_add(1, std::memory_order_relaxed);
    Store(shard, key, {c, true});
    Harvest(x, y, search);
    return c;
  }
  void Store(Shard& shard, uint64_t key, Cached value) {
    std::lock_guard<std::mutex> lock(shard.mu);
    auto it = shard.map.find(key);
    if (it != shard.map.end()) {
      it->second = value;
    } else if (cached_.load(std::memory_order_relaxed) < max_cached_) {
      shard.map.emplace(key, value);
      cached_.fetch_add(1, std::memory_order_relaxed);
    }
  }
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

thread_local std::vector<CellIndex> Problem::harvest_cells_;

// Internal unless a search's tour is consistent: the start first and the
// end last, each rank's two endpoints next to each other, positions and
// mates matching the order, and the cost the sum of its transition costs.
// Checked on every thread's tour and the shared incumbent before a tour is
// returned.
absl::Status AuditTour(int n, const std::vector<int>& t, const std::vector<int>& pos,
                       const std::vector<int>& mate, const std::vector<double>& lc, double cost) {
  const int nodes = 2 * n + 2;
  if (static_cast<int>(t.size()) != nodes || t.front() != 2 * n || t.back() != 2 * n + 1) {
    return absl::InternalError("sparse tour: the tour does not run from the start to the end");
  }
  std::vector<uint8_t> seen(nodes, 0);
  for (int i = 0; i < nodes; ++i) {
    const int v = t[i];
    if (v < 0 || v >= nodes || seen[v]) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: node %d visited twice or out of range", v));
    }
    seen[v] = 1;
    if (pos[v] != i) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: node %d is at %d, its position says %d", v, i, pos[v]));
    }
  }
  for (int i = 1; i + 1 < nodes; i += 2) {
    if (t[i + 1] != (t[i] ^ 1)) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: rank %d is not driven in one piece", t[i] / 2));
    }
  }
  double sum = 0.0;
  for (int i = 0; i < nodes; i += 2) {
    const int a = t[i], b = t[i + 1];
    if (mate[a] != b || mate[b] != a || lc[a] != lc[b]) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: transition %d -> %d is not linked", a, b));
    }
    sum += lc[a];
  }
  if (!(std::abs(sum - cost) <= 1e-6 * std::max(1.0, std::abs(sum)))) {
    return absl::InternalError(absl::StrFormat(
        "sparse tour: cost %.6f s is not the sum of its transitions, %.6f s", cost, sum));
  }
  return absl::OkStatus();
}

// The best tour of a kick phase shared by several threads: each kicks its
// copy of it, publishes a better tour, and copies a newer one before its
// next kick; `stale` counts the kicks of all threads since the last
// published gain, so the phase converges after as many kicks without gain
// as one thread's would, reached about threads times sooner.
struct Incumbent {
  std::mutex mu;
  std::vector<int> t, pos, mate;  // guarded by mu, as is cost
  std::vector<double> lc;
  double cost = std::numeric_limits<double>::infinity();
  std::atomic<uint64_t> version{0};  // bumped (under mu) by every publish
  std::atomic<int64_t> stale{0};
};

// One search run: a tour t = [S, entry, exit, entry, exit, ..., E] with
// positions, the mate of each node across its transition edge, and that
// edge's cost. Writes can be logged and undone (rejected kicks).

class Run {
 public:
  Run(Problem* p, uint64_t seed) : p_(*p), search_(p->grid()), rng_(seed) {
    const int nodes = 2 * p_.n() + 2;
    pos_.assign(nodes, 0);
    mate_.assign(nodes, -1);
    lc_.assign(nodes, 0.0);
    queued_.assign(nodes, 0);
  }

  absl::Status Construct(const StopToken& stop);
  // The tour `order` (entry endpoints in visiting order) as a cycle, cut at
  // its best place for S and E by lower bounds, either direction. False if
  // it does not visit every rank exactly once.
  bool ConstructFrom(const std::vector<int>& order);
  // Positions, mates and exact costs of the transitions of a complete t_.
  void PriceTour();
  void LocalSearch(const StopToken& stop);
  // Returns true if it converged (not stopped by the budget). With a
  // `shared` incumbent the run kicks its latest tour, publishes gains to it
  // and converges on its global count of kicks without gain.
  bool Iterate(const StopToken& stop, int64_t converge_after, bool until_limit,
               Incumbent* shared = nullptr);
  // Makes this run's tour the incumbent's if it is cheaper; true if it did.
  bool Publish(Incumbent* shared) {
    std::lock_guard<std::mutex> lock(shared->mu);
    if (!(cost_ < shared->cost - kEps)) return false;
    shared->t = t_, shared->pos = pos_, shared->mate = mate_, shared->lc = lc_,
    shared->cost = cost_;
    version_ = shared->version.load(std::memory_order_relaxed) + 1;
    shared->version.store(version_, std::memory_order_release);
    return true;
  }
  absl::Status Audit() const { return AuditTour(p_.n(), t_, pos_, mate_, lc_, cost_); }
  // Takes the incumbent's tour when it is newer than the one this run has.
  void Sync(Incumbent* shared) {
    if (shared->version.load(std::memory_order_acquire) == version_) return;
    std::lock_guard<std::mutex> lock(shared->mu);
    t_ = shared->t, pos_ = shared->pos, mate_ = shared->mate, lc_ = shared->lc,
    cost_ = shared->cost;
    version_ = shared->version.load(std::memory_order_relaxed);
  }
  double cost() const { return cost_; }
  int64_t kicks() const { return kicks_; }
  const std::vector<int>& tour() const { return t_; }
  // Starts from `other`'s tour (same problem).
  void CopyTour(const Run& other) {
    t_ = other.t_, pos_ = other.pos_, mate_ = other.mate_, lc_ = other.lc_, cost_ = other.cost_;
  }
  void PushAll(bool reversed) {
    if (reversed) {
      for (auto it = t_.rbegin(); it != t_.rend(); ++it) Push(*it);
    } else {
      for (int v : t_) Push(v);
    }
  }

 private:
  enum What : uint8_t { kT, kPos, kMate, kLc };
  struct Undo {
    What what;
    int32_t idx;
    double old;
  };
  void SetT(int i, int node) {
    if (logging_) log_.push_back({kT, i, static_cast<double>(t_[i])});
    t_[i] = node;
    if (logging_) log_.push_back({kPos, node, static_cast<double>(pos_[node])});
    pos_[node] = i;
  }
  void Link(int x, int y, double c) {
    for (int a : {x, y}) {
      if (logging_) {
        log_.push_back({kMate, a, static_cast<double>(mate_[a])});
        log_.push_back({kLc, a, lc_[a]});
      }
    }
    mate_[x] = y, mate_[y] = x, lc_[x] = c, lc_[y] = c;
  }
  void Rollback() {
    for (auto it = log_.rbegin(); it != log_.rend(); ++it) {
      switch (it->what) {
        case kT:
          t_[it->idx] = static_cast<int>(it->old);
          break;
        case kPos:
          pos_[it->idx] = static_cast<int>(it->old);
          break;
        case kMate:
          mate_[it->idx] = static_cast<int>(it->old);
          break;
        case kLc:
          lc_[it->idx] = it->old;
          break;
      }
    }
    log_.clear();
  }
  void Push(int node) {
    if (!queued_[node]) queued_[node] = 1, queue_.push_back(node);
  }
  double C(int x, int y) { return p_.ExactCost(x, y, &search_, *stop_); }
  double B(int x, int y) { return p_.ProbeCost(x, y, &search_); }
  // LowerCost through a direct-mapped memo: the local search asks for the
  // same pairs' bounds again and again (after every rolled-back kick), and
  // each costs an arc tangent and the straight-line time.
  double L(int x, int y) {
    const uint64_t key = (static_cast<uint64_t>(x) << 32 | static_cast<uint32_t>(y)) + 1;
    LowerMemo& m = lower_memo_[(key * 0x9E3779B97F4A7C15ULL) >> (64 - kLowerMemoBits)];
    if (m.key != key) m.key = key, m.value = p_.LowerCost(x, y);
    return m.value;
  }

  bool Improve(int x);
  bool TryTwoOpt(int i, int j);
  bool TryOrOpt(int a, int b, int k, bool reversed);
  void ApplyTwoOpt(int i, int j, double c1, double c2);
  void ApplyOrOpt(int a, int b, int k, bool reversed, double gap, double cl, double cr);
  void DoubleBridge(int i, int j, int k);

  Problem& p_;
  const StopToken* stop_ = &never_;  // bounds exact searches of the current phase
  StopToken never_;
  AnyAngleSearch search_;
  gtsp_internal::Rng rng_;
  std::vector<int> t_, pos_, mate_;
  std::vector<double> lc_;
  double cost_ = 0.0;
  int64_t kicks_ = 0;
  uint64_t version_ = 0;  // of the incumbent this run's tour came from
  bool logging_ = false;
  std::vector<Undo> log_;
  std::deque<int> queue_;
  std::vector<uint8_t> queued_;
  std::vector<int> scratch_;
  struct LowerMemo {
    uint64_t key = 0;  // (x << 32 | y) + 1; 0 = empty
    double value = 0.0;
  };
  static constexpr int kLowerMemoBits = 16;
  static_assert(sizeof(LowerMemo) << kLowerMemoBits == kSparseTourBytesPerThread);
  std::vector<LowerMemo> lower_memo_ = std::vector<LowerMemo>(size_t{1} << kLowerMemoBits);
};

absl::Status Run::Construct(const StopToken& stop) {
  const int n = p_.n();
  const Grid& grid = p_.grid();
  // Bucket grid of unvisited endpoints for the fallback when every
  // candidate of the current endpoint is already visited.
  const int side = std::max(
      4, static_cast<int>(std::sqrt(static_cast<double>(grid.size()) / std::max(1, 2 * n))));
  const int brows = grid.rows() / side + 1, bcols = grid.cols() / side + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(brows) * bcols);
  for (int e = 0; e < 2 * n; ++e) {
    const CellIndex c = p_.cell(e);
    buckets[static_cast<size_t>(c.row / side) * bcols + c.col / side].push_back(e);
  }
  std::vector<uint8_t> visited(n, 0);
  t_.clear();
  t_.push_back(p_.S());
  int cur = p_.S();
  std::vector<std::pair<double, int>> near;
  for (int step = 0; step < n; ++step) {
    if ((step & 255) == 255 && stop.cancelled())
      return absl::CancelledError("tour construction cancelled");
    int best = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    const absl::Span<const EndpointCandidate> cands = p_.candidates(cur);
    for (size_t i = 0; i < cands.size(); ++i) {
      if (visited[cands[i].endpoint / 2]) continue;
      const double cost = p_.CandidateCost(cur, i);
      if (cost < best_cost) best_cost = cost, best = cands[i].endpoint;
    }
    if (best < 0) {
      // Nearest unvisited endpoints by lower bound, ring by ring.
      const CellIndex at = p_.cell(cur);
      const int br = at.row / side, bc = at.col / side;
      near.clear();
      constexpr size_t kWant = 8;
      for (int r = 0; r <= std::max(brows, bcols); ++r) {
        for (int rr = br - r; rr <= br + r; ++rr) {
          if (rr < 0 || rr >= brows) continue;
          for (int cc = bc - r; cc <= bc + r; ++cc) {
            if (cc < 0 || cc >= bcols) continue;
            if (std::max(std::abs(rr - br), std::abs(cc - bc)) != r) continue;
            std::vector<int>& b = buckets[static_cast<size_t>(rr) * bcols + cc];
            for (size_t i = 0; i < b.size();) {
              if (visited[b[i] / 2]) {
                b[i] = b.back();
                b.pop_back();
                continue;
              }
              const double lb = L(cur, b[i]);
              if (std::isfinite(lb)) near.push_back({lb, b[i]});
              ++i;
            }
          }
        }
        if (near.size() >= kWant) {
          std::nth_element(near.begin(), near.begin() + (kWant - 1), near.end());
          // Endpoints beyond ring r are at least r * side cells away.
          if (p_.StraightCost(static_cast<float>(r * side)) >= near[kWant - 1].first) break;
        }
      }
      // Exact searches are the expensive part: price the two best by bound.
      std::sort(near.begin(), near.end());
      for (size_t i = 0; i < near.size() && i < 2; ++i) {
        if (near[i].first >= best_cost) break;
        const double cost = C(cur, near[i].second);
        if (cost < best_cost) best_cost = cost, best = near[i].second;
      }
      if (best < 0) {
        return absl::InvalidArgumentError(
            absl::StrFormat("rank %d cannot be reached from the start pose", [&] {
              for (int k = 0; k < n; ++k) {
                if (!visited[k]) return k;
              }
              return -1;
            }()));
      }
    }
    visited[best / 2] = 1;
    t_.push_back(best);
    t_.push_back(best ^ 1);
    cur = best ^ 1;
  }
  t_.push_back(p_.E());
  PriceTour();
  return absl::OkStatus();
}

void Run::PriceTour() {
  cost_ = 0.0;
  for (size_t i = 0; i < t_.size(); ++i) pos_[t_[i]] = static_cast<int>(i);
  for (size_t i = 0; i + 1 < t_.size(); i += 2) {
    const double c = C(t_[i], t_[i + 1]);
    Link(t_[i], t_[i + 1], c);
    cost_ += c;
  }
}

bool Run::ConstructFrom(const std::vector<int>& order) {
  const int n = p_.n();
  if (static_cast<int>(order.size()) != n || n == 0) return false;
  std::vector<uint8_t> seen(n, 0);
  for (int v : order) {
    if (v < 0 || v >= 2 * n || seen[v / 2]) return false;
    seen[v / 2] = 1;
  }
  // Entry of the k-th rank in direction d (0: as remembered, 1: reversed).
  auto entry = [&](int d, int k) { return d == 0 ? order[k] : order[n - 1 - k] ^ 1; };
  int best_d = 0, best_r = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 2; ++d) {
    for (int r = 0; r < n; ++r) {
      const int in = entry(d, r), out = entry(d, (r + n - 1) % n) ^ 1;
      const double c = L(p_.S(), in) + L(out, p_.E()) - (n > 1 ? L(out, in) : 0.0);
      if (c < best) best = c, best_d = d, best_r = r;
    }
  }
  t_.clear();
  t_.push_back(p_.S());
  for (int k = 0; k < n; ++k) {
    const int e = entry(best_d, (best_r + k) % n);
    t_.push_back(e);
    t_.push_back(e ^ 1);
  }
  t_.push_back(p_.E());
  PriceTour();
  return true;
}

void Run::ApplyTwoOpt(int i, int j, double c1, double c2) {
  // Reverse t[i+1..j]; the new edges are (t[i], old t[j]) and (old t[i+1], t[j+1]).
  const int a = t_[i], b = t_[i + 1], c = t_[j], d = t_[j + 1];
  for (int lo = i + 1, hi = j; lo < hi; ++lo, --hi) {
    const int x = t_[lo], y = t_[hi];
    SetT(lo, y);
    SetT(hi, x);
  }
  Link(a, c, c1);
  Link(b, d, c2);
}

bool Run::TryTwoOpt(int i, int j) {
  if (i > j) std::swap(i, j);
  if (j - i < 2 || i < 0 || j + 1 >= static_cast<int>(t_.size())) return false;
  const int a = t_[i], b = t_[i + 1], c = t_[j], d = t_[j + 1];
  const double removed = lc_[a] + lc_[c];
  const double lac = L(a, c), lbd = L(b, d);
  if (lac + lbd >= removed - kEps) return false;
  double c1, c2;
  // The pair known without a search first, so the bound can spare the other.
  if (p_.Known(b, d) && !p_.Known(a, c)) {
    c2 = C(b, d);
    if (B(a, c) + c2 >= removed - kEps) return false;
    c1 = C(a, c);
  } else {
    c1 = B(a, c);
    if (c1 + lbd >= removed - kEps) return false;
    if (B(b, d) + c1 >= removed - kEps) return false;
    c1 = C(a, c);
    if (c1 + lbd >= removed - kEps) return false;
    c2 = C(b, d);
  }
  if (c1 + c2 >= removed - kEps) return false;
  cost_ += c1 + c2 - removed;
  ApplyTwoOpt(i, j, c1, c2);
  for (int v : {a, b, c, d}) Push(v);
  return true;
}

void Run::ApplyOrOpt(int a, int b, int k, bool reversed, double gap, double cl, double cr) {
  const int before = t_[a - 1], after = t_[b + 1], left = t_[2 * k], right = t_[2 * k + 1];
  scratch_.assign(t_.begin() + a, t_.begin() + b + 1);
  if (reversed) std::reverse(scratch_.begin(), scratch_.end());
  const int first = scratch_.front(), last = scratch_.back();
  if (2 * k + 1 < a) {
    // Insert before: [2k+1, b] becomes seg + old [2k+1, a-1].
    std::vector<int> moved(t_.begin() + 2 * k + 1, t_.begin() + a);
    int w = 2 * k + 1;
    for (int v : scratch_) SetT(w++, v);
    for (int v : moved) SetT(w++, v);
  } else {
    // Insert after: [a, 2k] becomes old [b+1, 2k] + seg.
    std::vector<int> moved(t_.begin() + b + 1, t_.begin() + 2 * k + 1);
    int w = a;
    for (int v : moved) SetT(w++, v);
    for (int v : scratch_) SetT(w++, v);
  }
  Link(before, after, gap);
  Link(left, first, cl);
  Link(last, right, cr);
}

bool Run::TryOrOpt(int a, int b, int k, bool reversed) {
  const int size = static_cast<int>(t_.size());
  if (a < 1 || b + 1 >= size || k < 0 || 2 * k + 1 >= size) return false;
  if (!(2 * k + 1 < a - 1 || 2 * k > b)) return false;  // not next to or inside the segment
  const int before = t_[a - 1], after = t_[b + 1], left = t_[2 * k], right = t_[2 * k + 1];
  const int first = reversed ? t_[b] : t_[a], last = reversed ? t_[a] : t_[b];
  const double removed = lc_[before] + lc_[t_[b]] + lc_[left];
  const double lg = L(before, after), ll = L(left, first), lr = L(last, right);
  if (lg + ll + lr >= removed - kEps) return false;
  // Known pairs first (no search), then the rest while the bound allows.
  double cost[3] = {lg, ll, lr};
  const int xs[3] = {before, left, last}, ys[3] = {after, first, right};
  // Known pairs first, otherwise in edge order (a stable partition of three).
  int order[3];
  bool known[3];
  for (int e = 0; e < 3; ++e) known[e] = p_.Known(xs[e], ys[e]);
  int filled = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int e = 0; e < 3; ++e) {
      if (known[e] == (pass == 0)) order[filled++] = e;
    }
  }
  for (int o : order) {
    cost[o] = B(xs[o], ys[o]);
    if (cost[0] + cost[1] + cost[2] >= removed - kEps) return false;
  }
  for (int o : order) {
    cost[o] = C(xs[o], ys[o]);
    if (cost[0] + cost[1] + cost[2] >= removed - kEps) return false;
  }
  const double cg = cost[0], cl = cost[1], cr = cost[2];
  cost_ += cg + cl + cr - removed;
  ApplyOrOpt(a, b, k, reversed, cg, cl, cr);
  for (int v : {before, after, left, right, first, last}) Push(v);
  return true;
}

bool Run::Improve(int x) {
  const int p = pos_[x];
  const int last_pos = static_cast<int>(t_.size()) - 1;
  // 2-opt: a new transition edge (x, y) for a candidate y.
  const absl::Span<const EndpointCandidate> cands = p_.candidates(x);
  for (size_t ci = 0; ci < cands.size(); ++ci) {
    const int y = cands[ci].endpoint;
    const int q = pos_[y];
    if ((q & 1) != (p & 1) || q == p) continue;
    if (x != p_.E() && p_.CandidateCost(x, ci) >= lc_[x] - kEps) continue;  // no gain on x's side
    const int i = (p & 1) ? std::min(p, q) - 1 : std::min(p, q);
    const int j = (p & 1) ? std::max(p, q) - 1 : std::max(p, q);
    if (TryTwoOpt(i, j)) return true;
  }
  if (x >= p_.S()) return false;
  // Runs of 1-3 ranks starting (x an entry) or ending (x an exit) at x:
  // reverse in place, or move next to a candidate of either end.
  for (int len = 1; len <= 3; ++len) {
    int a, b;
    if (p & 1) {
      a = p, b = p + 2 * len - 1;
    } else {
      b = p, a = p - 2 * len + 1;
    }
    if (a < 1 || b >= last_pos) break;
    if (TryTwoOpt(a - 1, b)) return true;
    for (int end = 0; end < 2; ++end) {
      const int z = t_[end == 0 ? a : b];
      for (const EndpointCandidate& c : p_.candidates(z)) {
        const int q = pos_[c.endpoint];
        if (q >= a - 1 && q <= b + 1) continue;
        int k;
        bool reversed;
        if (end == 0) {
          // (y, first): after an exit y forwards; before an entry y reversed.
          if ((q & 1) == 0)
            k = q / 2, reversed = false;
          else
            k = (q - 1) / 2, reversed = true;
        } else {
          if (q & 1)
            k = (q - 1) / 2, reversed = false;
          else
            k = q / 2, reversed = true;
        }
        if (TryOrOpt(a, b, k, reversed)) return true;
      }
    }
  }
  return false;
}

void Run::LocalSearch(const StopToken& stop) {
  stop_ = &stop;
  int64_t pops = 0;
  while (!queue_.empty()) {
    if ((++pops & 15) == 0 && stop.ShouldStop()) break;
    const int x = queue_.front();
    queue_.pop_front();
    queued_[x] = 0;
    if (Improve(x)) Push(x);
  }
  for (int v : queue_) queued_[v] = 0;
  queue_.clear();
  stop_ = &never_;
}

void Run::DoubleBridge(int i, int j, int k) {
  // [.., t[i]] [t[i+1] .. t[j]] [t[j+1] .. t[k]] [t[k+1] ..]  ->  A C B D.
  const int a = t_[i], b1 = t_[i + 1], b2 = t_[j], c1 = t_[j + 1], c2 = t_[k], d = t_[k + 1];
  const double removed = lc_[a] + lc_[b2] + lc_[c2];
  const double x = C(a, c1), y = C(c2, b1), z = C(b2, d);
  std::vector<int> seg(t_.begin() + j + 1, t_.begin() + k + 1);
  seg.insert(seg.end(), t_.begin() + i + 1, t_.begin() + j + 1);
  for (size_t m = 0; m < seg.size(); ++m) SetT(i + 1 + static_cast<int>(m), seg[m]);
  Link(a, c1, x);
  Link(c2, b1, y);
  Link(b2, d, z);
  cost_ += x + y + z - removed;
  for (int v : {a, b1, b2, c1, c2, d}) Push(v);
}

bool Run::Iterate(const StopToken& stop, int64_t converge_after, bool until_limit,
                  Incumbent* shared) {
  const int n = p_.n();
  if (n < 4) return true;
  std::atomic<int64_t> own_stale{0};
  std::atomic<int64_t>& no_improve = shared != nullptr ? shared->stale : own_stale;
  while (!stop.ShouldStop()) {
    if (!until_limit && no_improve.load(std::memory_order_relaxed) >= converge_after) return true;
    if (shared != nullptr) Sync(shared);
    // A local double bridge A B C D -> A C B D at the transition edge
    // (t[i], t[i+1]) of a random endpoint: t[j+1] a candidate of t[i] and
    // t[k] a candidate of t[i+1] when the tour order allows, so two of the
    // three new edges are candidate pairs (no search) between close
    // endpoints; else the edges of two candidates of candidates.
    const int x = static_cast<int>(rng_.UniformInt(2 * n));
    auto pick = [&](int from) {
      absl::Span<const EndpointCandidate> c = p_.candidates(from);
      return c.empty() ? static_cast<int>(rng_.UniformInt(2 * n))
                       : c[rng_.UniformInt(static_cast<int>(c.size()))].endpoint;
    };
    const int i0 = pos_[x] & ~1;  // left end of x's transition edge
    int i = -1, j = -1, k = -1;
    for (int attempt = 0; attempt < 4 && i < 0; ++attempt) {
      const int q = pos_[pick(t_[i0])];
      if ((q & 1) == 0 || q < i0 + 3) continue;
      const int r = pos_[pick(t_[i0 + 1])];
      if ((r & 1) != 0 || r < q + 1) continue;
      i = i0, j = q - 1, k = r;
    }
    if (i < 0) {
      const int y = pick(x);
      const int z = pick(y);
      int e[3] = {i0, pos_[y] & ~1, pos_[z] & ~1};
      std::sort(e, e + 3);
      if (e[0] == e[1] || e[1] == e[2] || e[2] + 1 >= static_cast<int>(t_.size())) {
        ++no_improve;
        continue;
      }
      i = e[0], j = e[1], k = e[2];
    }
    const double saved = cost_;
    ++kicks_;
    logging_ = true;
    stop_ = &stop;
    DoubleBridge(i, j, k);
    LocalSearch(stop);
    logging_ = false;
    if (cost_ < saved - kEps && std::isfinite(cost_)) {
      log_.clear();
      // Shared: a gain counts once it beats the incumbent (another thread
      // may have published a better tour meanwhile; the next kick takes it).
      if (shared == nullptr || Publish(shared)) {
        no_improve = 0;
      } else {
        ++no_improve;
      }
    } else {
      Rollback();
      cost_ = saved;
      ++no_improve;
    }
  }
  return false;
}

// Appends the centres of `cells`.
void AppendCentres(const Grid& grid, const std::vector<CellIndex>& cells,
                   std::vector<Point2>* pts) {
  for (const CellIndex& c : cells) pts->push_back(grid.CellCenter(c));
}

}  // namespace

absl::StatusOr<SparseTour> PlanSparseRankTour(const Grid& drive, const std::vector<Rank>& ranks,
                                              const EndpointGraph& graph, const RobotModel& robot,
                                              const SparseTourOptions& options,
                                              const StopToken& stop) {
  if (ranks.empty()) return absl::InvalidArgumentError("no ranks to order");
  if (graph.num_endpoints() != static_cast<int>(2 * ranks.size())) {
    return absl::InvalidArgumentError("endpoint graph does not match the ranks");
  }
  Pose2 start;
  if (robot.start) {
    start = *robot.start;
  } else {
    const Point2 p = drive.CellCenter(ranks[0].first);
    start = {p.x, p.y, ranks[0].orientation == Orientation::kHorizontal ? 0.0 : M_PI / 2};
  }
  const Pose2 end = robot.end.value_or(start);
  absl::StatusOr<CellIndex> start_cell = JoinCell(drive, start, "start");
  if (!start_cell.ok()) return start_cell.status();
  absl::StatusOr<CellIndex> end_cell = JoinCell(drive, end, "end");
  if (!end_cell.ok()) return end_cell.status();
  const int n = static_cast<int>(ranks.size());
  const int start_comp = graph.component(*start_cell);
  for (int e = 0; e < 2 * n; ++e) {
    if (graph.endpoint_component(e) != start_comp) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "rank %d cannot be reached from the start pose (%.3f, %.3f)", e / 2, start.x, start.y));
    }
  }
  if (graph.component(*end_cell) != start_comp) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the end pose (%.3f, %.3f) cannot be reached from the start pose", end.x, end.y));
  }

  Problem problem(drive, ranks, graph, robot, options.max_cached_pairs);
  if (!problem.Prepare(start, *start_cell, end, *end_cell, stop)) {
    return absl::DeadlineExceededError("stopped while routing from the start pose");
  }

  const absl::Time began = absl::Now();
  const StopToken budget = stop.WithEarlierDeadline(began + absl::Seconds(options.time_limit_s));
  const int threads = options.local_search ? std::max(1, options.num_threads) : 1;

  // Kicks without gain, counted over all threads (they kick one shared
  // incumbent).
  const int64_t converge_after =
      std::max<int64_t>(options.min_kicks, static_cast<int64_t>(options.kicks_per_rank * n));
  Incumbent incumbent;
  struct Outcome {
    std::vector<int> tour;
    double cost = std::numeric_limits<double>::infinity();
    bool converged = true;
    absl::Status audit;
  };
  std::vector<Outcome> outcomes(threads);
  // One construction (deterministic: repeating it per thread would only
  // duplicate work), then per thread a descent from it, and the kick phase:
  // with one thread a plain iterated local search, with more each thread
  // kicks the shared incumbent with its own seed. The threads share the
  // cost cache.
  std::vector<std::unique_ptr<Run>> runs;
  for (int t = 0; t < threads; ++t) {
    runs.push_back(std::make_unique<Run>(&problem, gtsp_internal::SeedFor(options.seed, t)));
  }
  const bool warm = !options.warm_vertices.empty() && runs[0]->ConstructFrom(options.warm_vertices);
  if (!warm) RETURN_IF_ERROR(runs[0]->Construct(stop));
  const bool kicks = options.local_search && (!warm || options.warm_kicks);
  for (int t = 1; t < threads; ++t) runs[t]->CopyTour(*runs[0]);
  auto run = [&](int index) {
    Run& r = *runs[index];
    Outcome& out = outcomes[index];
    if (options.local_search) {
      // Every thread descends from the shared start, odd threads with the
      // work queue reversed (another local optimum), while the others' exact
      // costs land in the shared cache.
      r.PushAll(/*reversed=*/index % 2 == 1);
      r.LocalSearch(budget);
    }
    if (kicks) {
      Incumbent* shared = threads > 1 ? &incumbent : nullptr;
      // The better descent becomes the incumbent; a thread that finishes
      // its descent first kicks its own until the other's beats it, and
      // kicks without gain count again from the better one.
      if (shared != nullptr && r.Publish(shared)) shared->stale = 0;
      out.converged =
          !budget.ShouldStop() && r.Iterate(budget, converge_after, options.until_limit, shared);
    } else if (options.local_search) {
      out.converged = !budget.ShouldStop();  // the descent ran to its end
    }
    out.tour = r.tour();
    out.cost = r.cost();
    out.audit = r.Audit();
  };
  {
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(run, t);
    run(0);
    for (auto& t : pool) t.join();
  }
  for (const Outcome& o : outcomes) RETURN_IF_ERROR(o.audit);
  int best = -1;
  for (int t = 0; t < threads; ++t) {
    if (best < 0 || outcomes[t].cost < outcomes[best].cost - kEps) best = t;
  }
  // A thread's last tour may trail the incumbent (its last gain lost to a
  // better one published meanwhile).
  if (kicks && threads > 1 && incumbent.cost < outcomes[best].cost - kEps) {
    RETURN_IF_ERROR(
        AuditTour(n, incumbent.t, incumbent.pos, incumbent.mate, incumbent.lc, incumbent.cost));
    outcomes[best].tour = incumbent.t, outcomes[best].cost = incumbent.cost;
  }
  const std::vector<int>& t = outcomes[best].tour;

  // Materialise the tour's n + 1 transitions as any-angle paths.
  std::vector<std::vector<CellIndex>> legs(n + 1);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  auto materialise = [&] {
    AnyAngleSearch search(drive);
    for (int k = next++; k <= n && !failed; k = next++) {
      const CellIndex a = problem.cell(t[2 * k]), b = problem.cell(t[2 * k + 1]);
      if (a == b) {
        legs[k] = {a};
        continue;
      }
      if (!search.RunTo(a, b, stop)) {
        failed = true;
        return;
      }
      legs[k] = search.PathTo(b);
      if (legs[k].empty()) failed = true;
    }
  };
  {
    const int mthreads = std::max(1, std::min(options.num_threads, n + 1));
    std::vector<std::thread> pool;
    for (int i = 1; i < mthreads; ++i) pool.emplace_back(materialise);
    materialise();
    for (auto& th : pool) th.join();
  }
  if (failed) {
    if (stop.ShouldStop())
      return absl::DeadlineExceededError("stopped while computing the tour's transition paths");
    return absl::InternalError("a tour transition has no any-angle path");
  }

  SparseTour tour;
  tour.warm_started = warm;
  tour.surrogate_cost = outcomes[best].cost;
  tour.exact_searches = problem.searches();
  for (int k = 0; k < n; ++k) tour.vertices.push_back(t[2 * k + 1]);
  std::vector<Waypoint>& path = tour.path;
  Point2 at{start.x, start.y};
  double heading = start.theta;
  path.push_back({at.x, at.y, heading, SegmentKind::kStart, -1});
  auto drive_to = [&](const std::vector<Point2>& pts) {
    for (size_t i = 1; i < pts.size(); ++i) {
      const double dx = pts[i].x - at.x, dy = pts[i].y - at.y;
      if (std::hypot(dx, dy) < kMinSegmentM) continue;
      heading = std::atan2(dy, dx);
      at = pts[i];
      path.push_back({at.x, at.y, heading, SegmentKind::kTransition, -1});
    }
  };
  std::vector<Point2> pts;
  for (int k = 0; k <= n; ++k) {
    pts.clear();
    pts.push_back(at);
    if (k == 0) pts.push_back({start.x, start.y});
    AppendCentres(drive, legs[k], &pts);
    if (k == n) pts.push_back({end.x, end.y});
    drive_to(pts);
    if (k == n) break;
    const int v = t[2 * k + 1];
    const Point2 exit = drive.CellCenter(problem.cell(v ^ 1));
    heading = RankHeading(ranks[v / 2], v % 2 == 0);
    at = exit;
    path.push_back({exit.x, exit.y, heading, SegmentKind::kCoverage, v / 2});
  }

  bool converged = true;
  for (const Outcome& o : outcomes) converged = converged && o.converged;
  tour.stopped_early = !converged;
  if (converged) {
    tour.termination = Termination::Converged(
        !options.local_search ? "nearest-neighbour tour (no search)"
        : kicks               ? "sparse tour search converged"
                : "sparse warm start: the remembered tour, cut for this start, locally optimised");
  } else if (stop.cancelled()) {
    tour.termination = Termination::LimitReached(TerminationLimit::kCancelled,
                                                 "sparse tour search cancelled; best tour kept");
  } else if (stop.ShouldStop()) {
    tour.termination = Termination::LimitReached(TerminationLimit::kDeadline,
                                                 "sparse tour search stopped by the deadline");
  } else {
    tour.termination = Termination::LimitReached(TerminationLimit::kTime,
                                                 "sparse tour search used its whole time limit");
  }
  return tour;
}

}  // namespace covplan
