// The interface every coverage planner implements, and what the engine hands
// it. A planner gets a PlanContext: the request's common options (robot,
// budget, seed, threads, stop token), its own options struct, the coverage
// area (drive and cover grids, zones) and the artifact cache for whatever
// per-map data it derives (OARP: the rank partition and transitions). It
// returns a planner-neutral CoveragePlan: path, sweeps, termination and its
// own detail. The engine fills the statistics that follow from the path.
//
// A new planner is a folder under planner/ with a Planner subclass and an
// options struct, plus one line in planner/engine/registry.cc (and, for the
// API, its options message in the proto's oneof).
//
//   class MyPlanner final : public Planner {
//     std::string_view name() const override { return "mine"; }
//     std::shared_ptr<const PlannerOptions> DefaultOptions() const override;
//     absl::StatusOr<CoveragePlan> Plan(const PlanContext& ctx) const override;
//   };
//
// Thread-safety: planners are stateless (const methods called concurrently).
#ifndef COVPLAN_PLANNER_ENGINE_PLANNER_H_
#define COVPLAN_PLANNER_ENGINE_PLANNER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "planner/common/stop_token.h"
#include "planner/engine/artifact_cache.h"
#include "planner/engine/site.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

// Options every planner shares. Validate() names fields as the API does
// ("robot.tool_width_m", "time_limit_s"), so the edge can pass its message on.
struct CommonOptions {
  RobotModel robot;
  double min_free_fraction = 0.5;
  double time_limit_s = 1.0;  // search budget (also bounded by `stop`)
  uint64_t seed = 1;
  int num_threads = 1;
  StopToken stop;  // deadline / cancellation of the whole request

  static constexpr double kMaxTimeLimitS = 3600.0;
  // The one place these are validated; the API edge passes the messages on.
  absl::Status Validate() const;
};

// Base of each planner's own options struct.
class PlannerOptions {
 public:
  virtual ~PlannerOptions() = default;
  // InvalidArgument naming the field (e.g. "oarp.partition_solver").
  virtual absl::Status Validate() const = 0;
  // Every field, as stable text for cache keys (remembered plans): two
  // options with equal text must give equal plans.
  virtual std::string CacheText() const = 0;
};

// Limits of the host (server flags) that planners must respect.
struct EngineLimits {
  int64_t max_grid_cells = 4'000'000;
  // OARP: hard cap on coverage ranks. The transitions are bounded by memory
  // (below), not by this count.
  int64_t max_ranks = 100'000;
  // Memory budget of the transitions of one plan (OARP: the exact all-pairs
  // table and dense GTSP, or the sparse candidate graph with its search
  // scratch; boustrophedon: its all-pairs table). Above it: RESOURCE_EXHAUSTED.
  int64_t max_transition_bytes = int64_t{1} << 30;
  // OARP uses the exact all-pairs table and the dense GTSP while they fit in
  // this many bytes (about 100 ranks at the default), the sparse candidate
  // graph and tour search above (planner/tour/sparse_tour.h): on the IPA
  // buildings the sparse tours were within 0.2 % of the dense ones from 80
  // ranks up and 3-8x faster (docs/benchmarks.md §14).
  int64_t dense_transition_bytes = int64_t{4} << 20;
  int64_t max_area_vertices = 100'000;  // per regions / no_go / polygon map
  // Remember plans in the artifact cache (planner/engine/plan_memory.h);
  // false: every request searches from scratch.
  bool plan_memory = true;
};

struct PlanContext {
  const CommonOptions* common = nullptr;
  const PlannerOptions* options = nullptr;  // the planner's own type
  std::shared_ptr<const CoverageArea> area;
  ArtifactKey<CoverageArea> area_key = ArtifactKey<CoverageArea>::FromText("");
  ArtifactCache* cache = nullptr;
  EngineLimits limits;
  // Set to false by a planner when one of its artifacts had to be built.
  bool* all_cached = nullptr;
  // A remembered tour to start the search from (TourModel vertices in
  // visiting order, as CoveragePlan::tour_vertices; see plan_memory.h), or
  // null. Only planners whose SupportsWarmStart() is true read it.
  const std::vector<int>* warm_tour = nullptr;
  // With warm_tour: search trials to spend on it (OrdererOptions::warm_trials:
  // -1 = the effort's full count, to improve an identical request's plan;
  // 0 = only the local step).
  int warm_trials = 1;
};

class Planner {
 public:
  virtual ~Planner() = default;
  virtual std::string_view name() const = 0;
  virtual std::shared_ptr<const PlannerOptions> DefaultOptions() const = 0;
  // InvalidArgument unless `options` is this planner's options type.
  virtual absl::Status CheckOptions(const PlannerOptions& options) const = 0;
  // Builds (or finds in the cache) the planner's per-map artifacts; a host
  // may call it alone to warm the cache. Plan() calls it too.
  virtual absl::Status Prepare(const PlanContext& ctx) const = 0;
  virtual absl::StatusOr<CoveragePlan> Plan(const PlanContext& ctx) const = 0;
  // True when Plan() with these options honours PlanContext::warm_tour and
  // fills CoveragePlan::tour_vertices.
  virtual bool SupportsWarmStart(const PlannerOptions&) const { return false; }
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_PLANNER_H_
