#include "planner/partition/push_relabel_partitioner.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

// Per-cell state bits. An arc runs from a cell to its neighbour in +col
// (kArcCol) or +row (kArcRow); kFlowCol / kFlowRow say it carries its one
// unit. A source cell gets one unit from s; a sink cell drains one unit to t
// (kSinkUsed once it has). kQueued: in the FIFO of cells with excess.
constexpr uint8_t kArcCol = 1, kArcRow = 2, kSink = 4, kFlowCol = 8, kFlowRow = 16, kSinkUsed = 32,
                  kQueued = 64, kSource = 128;
// The residual arcs out of a cell: its free arcs forward, and the arcs that
// carry flow into it, backwards.
enum Residual : int8_t { kNone = -1, kForwardCol, kForwardRow, kBackRow, kBackCol };
constexpr uint32_t kPollMask = (1u << 14) - 1;  // poll the stop token every 16,384 steps

absl::Status Stopped() {
  return absl::DeadlineExceededError("partition stopped during push-relabel");
}

class GridFlow {
 public:
  // Arcs, sources and sinks of `grid`'s cut graph; `constant` and the
  // initial excess (one unit on every source cell) are set here.
  explicit GridFlow(const Grid& grid) : cols_(grid.cols()), n_(static_cast<int32_t>(grid.size())) {
    state_.assign(n_, 0);
    excess_.assign(n_, 0);
    for (int r = 0; r < grid.rows(); ++r) {
      for (int c = 0; c < grid.cols(); ++c) {
        if (!grid.IsFree(r, c)) continue;
        const int32_t i = static_cast<int32_t>(grid.Index(r, c));
        const bool next_col = grid.Passable(r, c, 0, 1), next_row = grid.Passable(r, c, 1, 0);
        const bool prev_col = grid.Passable(r, c, 0, -1);
        ++free_cells_;
        uint8_t s = (next_col ? kArcCol : 0) | (next_row ? kArcRow : 0);
        // ranks = free - links + (cells linked in -col and +row) + max flow;
        // the header derives the terms.
        constant_ -= static_cast<int64_t>(next_col) + static_cast<int64_t>(next_row);
        if (prev_col && next_row) ++constant_;
        if (next_row && !prev_col) s |= kSource, excess_[i] = 1, sources_.push_back(i);
        if (prev_col && !next_row) s |= kSink, sinks_.push_back(i);
        state_[i] = s;
      }
    }
    constant_ += free_cells_;
    kInf_ = n_ + 2;
    label_.assign(n_, kInf_);
    seen_.assign((static_cast<size_t>(n_) + 63) / 64, 0);
  }

  int64_t free_cells() const { return free_cells_; }

  // Phase one of push-relabel: a maximum preflow. Returns the flow into t.
  absl::StatusOr<int64_t> MaxPreflow(const StopToken& stop) {
    // On open ground every source, or every sink, may be served along
    // forward arcs alone (an empty lawn: nested L-shaped paths); a greedy
    // pass then is a maximum flow, as no flow can exceed the sources' or the
    // sinks' count. It stops at the first source it cannot route, and
    // unless every sink is used by then its flow is undone: elsewhere its
    // long greedy paths cost more pushes to reroute than they save
    // (docs/benchmarks.md §1d).
    ASSIGN_OR_RETURN(const bool every_source, GreedyRoutesEverySource(stop));
    if (!every_source && flow_ < static_cast<int64_t>(sinks_.size())) UndoFlow();
    if (!GlobalRelabel(stop)) return Stopped();
    std::vector<int32_t> queue;
    for (int32_t i : sources_) {
      if (label_[i] < kInf_) queue.push_back(i), state_[i] |= kQueued;
    }
    // A global relabelling costs one pass over the grid; n / 24 relabels
    // between two was the fastest of n / 6 ... n / 96 on 10^6-cell fields
    // and buildings (docs/benchmarks.md §1d).
    const int64_t relabels_per_global = std::max<int64_t>(n_ / 24, 64);
    int64_t relabels = 0;
    uint32_t steps = 0;
    size_t head = 0;
    while (head < queue.size()) {
      const int32_t u = queue[head++];
      state_[u] &= static_cast<uint8_t>(~kQueued);
      while (excess_[u] > 0 && label_[u] < kInf_) {
        if ((++steps & kPollMask) == 0 && stop.ShouldStop()) return Stopped();
        if ((state_[u] & (kSink | kSinkUsed)) == kSink && label_[u] == 1) {
          state_[u] |= kSinkUsed, --excess_[u], ++flow_;
          continue;
        }
        const Residual arc = AdmissibleOrRelabel(u);
        if (arc == kNone) {
          ++relabels;
          continue;
        }
        const int32_t v = Push(u, arc);
        if (!(state_[v] & kQueued)) state_[v] |= kQueued, queue.push_back(v);
      }
      if (relabels >= relabels_per_global) {
        relabels = 0;
        if (!GlobalRelabel(stop)) return Stopped();
        // Excess that can no longer reach t stays where it is: phase one
        // needs only the flow into t and the cut.
        size_t kept = 0;
        for (size_t q = head; q < queue.size(); ++q) {
          const int32_t w = queue[q];
          if (label_[w] < kInf_) {
            queue[kept++] = w;
          } else {
            state_[w] &= static_cast<uint8_t>(~kQueued);
          }
        }
        queue.resize(kept);
        head = 0;
      } else if (head > 4096 && head * 2 > queue.size()) {
        queue.erase(queue.begin(), queue.begin() + static_cast<std::ptrdiff_t>(head));
        head = 0;
      }
    }
    return flow_;
  }

  // After MaxPreflow, the orientation of a minimum cut: H (0) for the cells
  // that can still reach t in the residual graph (the sink side), else V (1).
  absl::StatusOr<std::vector<uint8_t>> CutOrientation(const StopToken& stop) {
    if (!GlobalRelabel(stop)) return Stopped();
    std::vector<uint8_t> orientation(n_, 0);
    for (int32_t i = 0; i < n_; ++i) orientation[i] = label_[i] < kInf_ ? 0 : 1;
    return orientation;
  }

  int64_t constant() const { return constant_; }

  // push_relabel_internal::AuditDamagedFlow: false when no cell fits.
  bool Damage(push_relabel_internal::FlowDamage damage) {
    using push_relabel_internal::FlowDamage;
    for (int32_t i = 0; i < n_; ++i) {
      uint8_t& s = state_[i];
      switch (damage) {
        case FlowDamage::kNone:
          return true;
        case FlowDamage::kFlowOnMissingArc:
          if (i % cols_ + 1 < cols_ && !(s & kArcCol)) return s |= kFlowCol, true;
          break;
        case FlowDamage::kUnitLost:
          if (s & kFlowRow) return s &= static_cast<uint8_t>(~kFlowRow), true;
          break;
        case FlowDamage::kExtraUnitToT:
          if ((s & (kSink | kSinkUsed)) == kSink) return s |= kSinkUsed, ++flow_, true;
          break;
      }
    }
    return false;
  }

  // Internal unless the preflow is feasible: flow only on arcs, at most the
  // arc's one unit (a bit); into every cell as much as out of it plus its
  // excess, which is never negative; and the units counted into t are the
  // sinks used. The rank check after the cut is a proof of optimality only
  // for a feasible flow.
  absl::Status AuditFlow() const {
    int64_t sinks_used = 0;
    for (int32_t i = 0; i < n_; ++i) {
      const uint8_t s = state_[i];
      if (((s & kFlowCol) && !(s & kArcCol)) || ((s & kFlowRow) && !(s & kArcRow))) {
        return absl::InternalError(
            absl::StrFormat("push-relabel: flow on a missing arc at cell %d", i));
      }
      if ((s & kSinkUsed) && !(s & kSink)) {
        return absl::InternalError(
            absl::StrFormat("push-relabel: flow to t from a non-sink cell %d", i));
      }
      sinks_used += (s & kSinkUsed) != 0;
      const int in = ((s & kSource) ? 1 : 0) + (i > 0 && (state_[i - 1] & kFlowCol) ? 1 : 0) +
                     (i >= cols_ && (state_[i - cols_] & kFlowRow) ? 1 : 0);
      const int out =
          ((s & kFlowCol) ? 1 : 0) + ((s & kFlowRow) ? 1 : 0) + ((s & kSinkUsed) ? 1 : 0);
      if (excess_[i] < 0 || in - out != excess_[i]) {
        return absl::InternalError(
            absl::StrFormat("push-relabel: flow not conserved at cell %d", i));
      }
    }
    if (sinks_used != flow_) {
      return absl::InternalError(
          absl::StrFormat("push-relabel: %d units into t but %d sinks used", flow_, sinks_used));
    }
    return absl::OkStatus();
  }

 private:
  // Routes the sources' units along free forward arcs (+row first, then
  // +col) to unused sinks by depth-first search; a cell found to lead to no
  // sink is marked and never entered again, so the pass is O(cells). False
  // at the first source it cannot route.
  absl::StatusOr<bool> GreedyRoutesEverySource(const StopToken& stop) {
    std::fill(seen_.begin(), seen_.end(), 0);  // here: cells that lead to no sink
    std::vector<int32_t> path;
    std::vector<uint8_t> arcs;  // arcs[k]: kFlowCol or kFlowRow from path[k] to path[k + 1]
    uint32_t steps = 0;
    for (int32_t src : sources_) {
      path.assign(1, src);
      arcs.clear();
      while (true) {
        if ((++steps & kPollMask) == 0 && stop.ShouldStop()) return Stopped();
        if (path.empty()) return false;
        const int32_t u = path.back();
        if ((state_[u] & (kSink | kSinkUsed)) == kSink) {
          state_[u] |= kSinkUsed, ++flow_, --excess_[src];
          for (size_t k = 0; k < arcs.size(); ++k) state_[path[k]] |= arcs[k];
          break;
        }
        const uint8_t s = state_[u];
        if ((s & (kArcRow | kFlowRow)) == kArcRow && !Seen(u + cols_)) {
          path.push_back(u + cols_), arcs.push_back(kFlowRow);
        } else if ((s & (kArcCol | kFlowCol)) == kArcCol && !Seen(u + 1)) {
          path.push_back(u + 1), arcs.push_back(kFlowCol);
        } else {
          MarkSeen(u);
          path.pop_back();
          if (!arcs.empty()) arcs.pop_back();
        }
      }
    }
    return true;
  }

  void UndoFlow() {
    for (uint8_t& s : state_) s &= static_cast<uint8_t>(~(kFlowCol | kFlowRow | kSinkUsed));
    for (int32_t src : sources_) excess_[src] = 1;
    flow_ = 0;
  }

  // The first residual arc out of u that goes one label down. If there is
  // none, u is relabelled to one above its lowest residual neighbour (t
  // counts as label 0 while u's sink arc is unused) and kNone is returned.
  Residual AdmissibleOrRelabel(int32_t u) {
    const int32_t want = label_[u] - 1;
    const uint8_t s = state_[u];
    int32_t lowest = (s & (kSink | kSinkUsed)) == kSink ? 0 : kInf_;
    auto down = [&](int32_t v) {
      const int32_t l = label_[v];
      lowest = std::min(lowest, l);
      return l == want;
    };
    if ((s & (kArcCol | kFlowCol)) == kArcCol && down(u + 1)) return kForwardCol;
    if ((s & (kArcRow | kFlowRow)) == kArcRow && down(u + cols_)) return kForwardRow;
    if (u >= cols_ && (state_[u - cols_] & kFlowRow) && down(u - cols_)) return kBackRow;
    if (u > 0 && (state_[u - 1] & kFlowCol) && down(u - 1)) return kBackCol;
    label_[u] = std::min(lowest + 1, kInf_);
    return kNone;
  }

  // Sends one unit out of u along `arc`: along a free arc, or back along an
  // arc that carries flow into u. Returns the cell it reaches.
  int32_t Push(int32_t u, Residual arc) {
    int32_t v = u;
    switch (arc) {
      case kForwardCol:
        v = u + 1, state_[u] |= kFlowCol;
        break;
      case kForwardRow:
        v = u + cols_, state_[u] |= kFlowRow;
        break;
      case kBackRow:
        v = u - cols_, state_[v] &= static_cast<uint8_t>(~kFlowRow);
        break;
      case kBackCol:
        v = u - 1, state_[v] &= static_cast<uint8_t>(~kFlowCol);
        break;
      case kNone:
        return u;
    }
    --excess_[u], ++excess_[v];
    return v;
  }

  // One bit per cell in `seen_`, for the pass at hand.
  bool Seen(int32_t u) const { return (seen_[static_cast<uint32_t>(u) >> 6] >> (u & 63)) & 1; }
  void MarkSeen(int32_t u) { seen_[static_cast<uint32_t>(u) >> 6] |= uint64_t{1} << (u & 63); }

  // Exact distances to t in the residual graph, by one breadth-first search
  // backwards from the unused sinks; kInf_ where t is out of reach. Visited
  // marks live in a bitmap (n / 8 bytes, cache resident) and the queue is
  // walked a level at a time, so the labels are only written.
  bool GlobalRelabel(const StopToken& stop) {
    if (stop.ShouldStop()) return false;
    std::fill(label_.begin(), label_.end(), kInf_);
    std::fill(seen_.begin(), seen_.end(), 0);
    bfs_.clear();
    auto reach = [&](int32_t u) {
      if (!Seen(u)) MarkSeen(u), bfs_.push_back(u);
    };
    for (int32_t i : sinks_) {
      if (!(state_[i] & kSinkUsed)) reach(i);
    }
    size_t q = 0;
    for (int32_t level = 1; q < bfs_.size(); ++level) {
      const size_t level_end = bfs_.size();
      for (; q < level_end; ++q) {
        if ((q & kPollMask) == kPollMask && stop.ShouldStop()) return false;
        const int32_t v = bfs_[q];
        label_[v] = level;
        // Residual arcs u -> v: a free arc from v - 1 or v - cols, or flow
        // v -> v + 1 or v -> v + cols that can be sent back.
        if (v > 0 && (state_[v - 1] & (kArcCol | kFlowCol)) == kArcCol) reach(v - 1);
        if (v >= cols_ && (state_[v - cols_] & (kArcRow | kFlowRow)) == kArcRow) reach(v - cols_);
        const uint8_t s = state_[v];
        if (s & kFlowCol) reach(v + 1);
        if (s & kFlowRow) reach(v + cols_);
      }
    }
    return true;
  }

  const int32_t cols_, n_;
  int32_t kInf_ = 0;
  std::vector<uint8_t> state_;
  std::vector<int8_t> excess_;  // at most 2: two units in (a source cell has no -col arc)
  std::vector<int32_t> label_, sources_, sinks_, bfs_;
  std::vector<uint64_t> seen_;
  int64_t free_cells_ = 0, constant_ = 0, flow_ = 0;
};

}  // namespace

namespace push_relabel_internal {

absl::Status AuditDamagedFlow(const Grid& grid, FlowDamage damage) {
  if (grid.size() == 0 || grid.CountFree() == 0)
    return absl::FailedPreconditionError("no free cell");
  GridFlow flow(grid);
  RETURN_IF_ERROR(flow.MaxPreflow(StopToken()).status());
  if (!flow.Damage(damage)) return absl::FailedPreconditionError("no cell to damage");
  return flow.AuditFlow();
}

}  // namespace push_relabel_internal

absl::StatusOr<RankPartition> PushRelabelPartitioner::Partition(const Grid& grid,
                                                                const StopToken& stop) const {
  if (grid.size() == 0) return absl::InvalidArgumentError("grid is empty");
  if (grid.size() > INT32_MAX / 2)
    return absl::InvalidArgumentError("grid too large for push-relabel");
  if (stop.ShouldStop())
    return absl::DeadlineExceededError("partition stopped before push-relabel");
  GridFlow flow(grid);
  if (flow.free_cells() == 0) return absl::InvalidArgumentError("grid has no free cell");
  ASSIGN_OR_RETURN(const int64_t value, flow.MaxPreflow(stop));
  RETURN_IF_ERROR(flow.AuditFlow());
  ASSIGN_OR_RETURN(std::vector<uint8_t> orientation, flow.CutOrientation(stop));
  return CheckedPartition(grid, std::move(orientation), flow.constant() + value, "push-relabel");
}

}  // namespace covplan
