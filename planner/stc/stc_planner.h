// Spanning Tree Coverage (Gabriely & Rimon, seed 002), registered as "stc".
//
// Coarse cells of twice the tool width, each 2x2 cells of the engine's
// tool-width drive grid; a spanning tree of the coarse cells by DFS (the
// paper's on-line order) or by Prim with links along a sweep direction
// preferred; the tool circumnavigates the tree counter-clockwise and visits
// every sub-cell of every wholly free coarse cell exactly once (path length
// 4·N·D for N such cells on a closed tour). Partly free coarse cells stay in
// the tree: their free sub-cells are covered, the gaps bridged by shortest
// drive-grid paths (stc_walk.h). A coarse cell whose free sub-cells are not
// connected inside it (a thin wall through it, diagonal sub-cells) is no
// tree node: its sub-cells are "orphans", swept by excursions from the tree
// next to them; trees the coarse graph falls into are spliced into the walk
// where it meets them. The detail reports the extra moves and the sub-cells
// covered twice. The coarse grid can sit at four offsets against the tool
// grid; the planner tries all four and keeps the walk with the fewest moves.
// No per-map artifacts: planning is linear in the grid (plus the bridges).
//
//   auto opts = std::make_shared<StcOptions>();
//   opts->tree = StcTreeMethod::kPrim; opts->sweep_direction = SweepDirection::kVertical;
//   request.planner = "stc"; request.options = opts;
//
// Thread-safety: StcPlanner is stateless.
#ifndef COVPLAN_PLANNER_STC_STC_PLANNER_H_
#define COVPLAN_PLANNER_STC_STC_PLANNER_H_

#include <memory>
#include <string_view>

#include "planner/engine/planner.h"
#include "planner/stc/coarse_grid.h"
#include "planner/stc/spanning_tree.h"
#include "planner/stc/stc_walk.h"

namespace covplan {

struct StcOptions final : PlannerOptions {
  StcTreeMethod tree = StcTreeMethod::kDfs;
  SweepDirection sweep_direction = SweepDirection::kHorizontal;  // Prim only
  PartialCells partial_cells = PartialCells::kCover;
  // Try the four offsets of the coarse grid and keep the shortest walk;
  // false: coarse cells start at row 0, column 0.
  bool search_offset = true;
  absl::Status Validate() const override;
  std::string CacheText() const override;
};

class StcDetail final : public PlannerDetail {
 public:
  StcTreeMethod tree = StcTreeMethod::kDfs;
  SweepDirection sweep_direction = SweepDirection::kHorizontal;
  PartialCells partial_cells = PartialCells::kCover;
  CellIndex offset;                  // of the coarse grid (0 or 1 per axis)
  int64_t coarse_cells = 0;          // tree nodes
  int64_t full_coarse_cells = 0;     // nodes whose four sub-cells are free
  int64_t partial_coarse_cells = 0;  // nodes with 1-3 free sub-cells
  int64_t orphan_cells = 0;          // free sub-cells outside every node, swept by excursions
  int64_t tree_edges = 0;
  int64_t trees = 0;                   // components (1 unless partial cells are discarded)
  int64_t extra_moves = 0;             // moves that cover nothing new before the last new cell
  int64_t subcells_covered_twice = 0;  // sub-cells entered more than once while covering
  int64_t discarded_cells = 0;         // cells to cover never swept (PartialCells::kDiscard)
  size_t MemoryBytes() const override { return sizeof(*this); }
};

// Off-line STC on a drive grid (where the robot may go) for the cells of
// `cover` (same shape): the walk of the best offset and its detail. The walk
// starts at `start_cell` and ends at `end_cell` (both free drive cells).
struct StcOutcome {
  StcWalk walk;
  std::shared_ptr<StcDetail> detail;
  bool stopped = false;  // the stop token ended the offset search early
};
absl::StatusOr<StcOutcome> RunOfflineStc(const Grid& drive, const Grid& cover,
                                         const StcOptions& options, CellIndex start_cell,
                                         CellIndex end_cell, const StopToken& stop);

// The cell an STC tour starts at without a start pose: the first cell to
// cover in row-major order. NotFound when there is none.
absl::StatusOr<CellIndex> DefaultStartCell(const Grid& drive, const Grid& cover);

class StcPlanner final : public Planner {
 public:
  static constexpr std::string_view kName = "stc";
  std::string_view name() const override { return kName; }
  std::shared_ptr<const PlannerOptions> DefaultOptions() const override;
  absl::Status CheckOptions(const PlannerOptions& options) const override;
  absl::Status Prepare(const PlanContext&) const override { return absl::OkStatus(); }
  absl::StatusOr<CoveragePlan> Plan(const PlanContext& ctx) const override;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_STC_STC_PLANNER_H_
