// Boustrophedon coverage (Choset & Pignon; the cells of BC Sweep): a sweep-
// line decomposition of the cells to cover into cells that open and close
// at connectivity changes (decomposition.h), an ox-plow path per cell with a
// sweep axis chosen per cell (ox_plow.h), and the cells toured by the anytime
// GTSP over CellTourModel elements (each cell entered at any of its four
// corners: either end of the first or of the last line), priced by the robot's time model,
// transitions on the drive grid. A cell is always swept whole, in one visit. Registered as
// "boustrophedon".
//
// Per-map artifact, derived from the request's CoverageArea key:
//   ...|bcd()   the decomposition of the cover grid
//
//   BoustrophedonOptions o; o.sweep_axis = BoustrophedonAxis::kAuto;
//   request.planner = "boustrophedon"; request.options = std::make_shared<BoustrophedonOptions>(o);
//
// Thread-safety: BoustrophedonPlanner is stateless; artifacts are immutable.
#ifndef COVPLAN_PLANNER_BOUSTROPHEDON_BOUSTROPHEDON_PLANNER_H_
#define COVPLAN_PLANNER_BOUSTROPHEDON_BOUSTROPHEDON_PLANNER_H_

#include <memory>
#include <string_view>
#include <vector>

#include "planner/boustrophedon/decomposition.h"
#include "planner/boustrophedon/ox_plow.h"
#include "planner/engine/planner.h"
#include "planner/tour/gtsp/gtsp.h"
#include "planner/tour/tour_solver.h"

namespace covplan {

enum class BoustrophedonAxis { kAuto = 0, kVertical = 1, kHorizontal = 2 };

struct BoustrophedonOptions final : PlannerOptions {
  // kAuto: per cell, the axis with fewer lines; kVertical / kHorizontal:
  // that axis wherever the cell allows it.
  BoustrophedonAxis sweep_axis = BoustrophedonAxis::kAuto;
  TourSolver tour_solver = TourSolver::kGtsp;
  GtspEffort tour_effort = GtspEffort::kDefault;
  absl::Status Validate() const override;
  std::string CacheText() const override;
};

struct BoustrophedonCellInfo {
  BcdCell cell;
  SweepAxis axis = SweepAxis::kVertical;
  int num_lines = 0;
};

class BoustrophedonDetail final : public PlannerDetail {
 public:
  std::vector<BoustrophedonCellInfo> cells;
  std::vector<int> cell_order;      // visiting order (indices into cells)
  std::vector<bool> cell_mirrored;  // per visit: ox-plow path started at the first line's other end
  std::vector<bool> cell_reversed;  // per visit: ox-plow path driven from its end
  size_t MemoryBytes() const override;
};

class DecompositionArtifact final : public Artifact {
 public:
  std::shared_ptr<const BoustrophedonDecomposition> decomposition;
  double build_ms = 0.0;
  size_t MemoryBytes() const override { return sizeof(*this) + decomposition->MemoryBytes(); }
};

class BoustrophedonPlanner final : public Planner {
 public:
  static constexpr std::string_view kName = "boustrophedon";
  std::string_view name() const override { return kName; }
  std::shared_ptr<const PlannerOptions> DefaultOptions() const override;
  absl::Status CheckOptions(const PlannerOptions& options) const override;
  absl::Status Prepare(const PlanContext& ctx) const override;
  absl::StatusOr<CoveragePlan> Plan(const PlanContext& ctx) const override;

 private:
  absl::StatusOr<std::shared_ptr<const DecompositionArtifact>> GetDecomposition(
      const PlanContext& ctx) const;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_BOUSTROPHEDON_BOUSTROPHEDON_PLANNER_H_
