// The local search of the sparse rank tour (planner/tour/sparse_tour.h) over
// the costs of a SparseCostOracle: a nearest-neighbour construction (with a
// bucket-grid fallback to the nearest unvisited endpoints when every
// candidate is visited) or a remembered tour cut for this start and end,
// then 2-opt and Or-opt (1-3 ranks, either direction) on the candidate
// lists driven by a work queue, then iterated local search with local
// double-bridge kicks and undo. Several runs may kick one shared Incumbent.
// Moves are priced by lower bound, then probe, then exactly, so full
// searches run only for moves that could still improve.
//
//   SearchRun run(&oracle, seed);
//   RETURN_IF_ERROR(run.Construct(stop));
//   run.PushAll(false);
//   run.LocalSearch(budget);
//   run.Iterate(budget, converge_after, /*until_limit=*/false);
//   RETURN_IF_ERROR(run.Audit());
//
// Thread-safety: a SearchRun is single-threaded; runs on several threads
// share one oracle and, through its mutex, one Incumbent.
#ifndef COVPLAN_PLANNER_TOUR_SPARSE_LOCAL_SEARCH_H_
#define COVPLAN_PLANNER_TOUR_SPARSE_LOCAL_SEARCH_H_

#include <atomic>
#include <cstdint>
#include <deque>
#include <limits>
#include <mutex>
#include <vector>

#include "absl/status/status.h"
#include "planner/common/stop_token.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/gtsp/rng.h"
#include "planner/tour/sparse_cost_oracle.h"
#include "planner/tour/sparse_tour.h"

namespace covplan {
namespace sparse_internal {

// Cost differences below this are no gain.
inline constexpr double kCostEps = 1e-7;

// Internal unless a search's tour is consistent: the start first and the
// end last, each rank's two endpoints next to each other, positions and
// mates matching the order, and the cost the sum of its transition costs.
// Checked on every thread's tour and the shared incumbent before a tour is
// returned.
absl::Status AuditTour(int n, const std::vector<int>& t, const std::vector<int>& pos,
                       const std::vector<int>& mate, const std::vector<double>& lc, double cost);

// The best tour of a kick phase shared by several threads: each kicks its
// copy of it, publishes a better tour, and copies a newer one before its
// next kick; `stale` counts the kicks of all threads since the last
// published gain (the driver converges after one thread's count per
// thread, sparse_tour.cc).
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
class SearchRun {
 public:
  SearchRun(SparseCostOracle* p, uint64_t seed) : p_(*p), search_(p->grid()), rng_(seed) {
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
  bool Publish(Incumbent* shared);
  absl::Status Audit() const;
  // Takes the incumbent's tour when it is newer than the one this run has.
  void Sync(Incumbent* shared);
  double cost() const { return cost_; }
  int64_t kicks() const { return kicks_; }
  const std::vector<int>& tour() const { return t_; }
  // Starts from `other`'s tour (same problem).
  void CopyTour(const SearchRun& other);
  // Queues every node for the descent (in tour order or reversed).
  void PushAll(bool reversed);

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
  void Rollback();
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

  SparseCostOracle& p_;
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

}  // namespace sparse_internal
}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_SPARSE_LOCAL_SEARCH_H_
