// All-pairs transition paths between rank endpoints: the expensive, per-map
// part of tour planning, computed once and shared.
//
// Endpoint 2k is ranks[k].first, 2k+1 is ranks[k].last. One any-angle search
// (Lazy Theta*) runs per distinct endpoint cell, in parallel, and keeps for
// every ordered endpoint pair the path length and its corner cells. Times are
// not stored: they depend on the robot model and are derived per request
// (see RankTourCost), so one table serves every robot with this tool width.
//
//   ASSIGN_OR_RETURN(auto table, TransitionTable::Build(grid, ranks, stop, 2));
//   table->AppendPath(a, b, &cells);   // a's cell, corners..., b's cell
//
// Thread-safety: immutable after Build; const methods are thread-safe.
#ifndef COVPLAN_PLANNER_TOUR_TRANSITIONS_H_
#define COVPLAN_PLANNER_TOUR_TRANSITIONS_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"

namespace covplan {

class TransitionTable {
 public:
  static absl::StatusOr<std::shared_ptr<const TransitionTable>> Build(
      const Grid& grid, const std::vector<Rank>& ranks, const StopToken& stop, int num_threads);
  // The same over arbitrary endpoint cells (tour elements other than ranks).
  static absl::StatusOr<std::shared_ptr<const TransitionTable>> BuildForEndpoints(
      const Grid& grid, std::vector<CellIndex> endpoints, const StopToken& stop, int num_threads);

  int num_endpoints() const { return num_endpoints_; }
  CellIndex endpoint(int e) const { return endpoints_[e]; }
  bool Reachable(int a, int b) const { return pairs_[Pair(a, b)].length >= 0.0f; }
  // Path length in cells (times cell size = metres); -1 if unreachable.
  float LengthCells(int a, int b) const { return pairs_[Pair(a, b)].length; }
  // Appends the path a -> b as cells: a, intermediate corners, b.
  void AppendPath(int a, int b, std::vector<CellIndex>* out) const;

  size_t MemoryBytes() const;
  // Rough size of a table over `num_endpoints` endpoints: the pair records
  // plus ~8 corner cells per path (71-85 bytes per pair measured on the IPA
  // building maps at 0.2-0.8 m tools).
  static int64_t EstimateBytes(int num_endpoints) {
    const int64_t e = num_endpoints;
    return e * e * static_cast<int64_t>(sizeof(PairInfo) + 8 * sizeof(CellIndex));
  }

 private:
  struct PairInfo {
    float length = -1.0f;
    uint32_t offset = 0;  // into corners_[a]
    uint32_t count = 0;   // intermediate corners
  };
  size_t Pair(int a, int b) const { return static_cast<size_t>(a) * num_endpoints_ + b; }

  int num_endpoints_ = 0;
  std::vector<CellIndex> endpoints_;
  std::vector<PairInfo> pairs_;
  std::vector<std::vector<CellIndex>> corners_;  // per search source endpoint
  std::vector<int> alias_;  // endpoint -> endpoint whose search (corner list) it shares
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_TOUR_TRANSITIONS_H_
