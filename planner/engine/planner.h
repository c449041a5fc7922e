// The interface every coverage planner implements, and what the engine hands
// it. A planner gets a PlanContext: the request's common options (robot,
// budget, seed, threads, stop token), its own options struct, the coverage
// area (drive and cover grids, zones) and the artifact cache for whatever
// per-map data it derives (OARP: the rank partition and transitions). It
// returns a planner-neutral CoveragePlan: path, sweeps, termination and its
// own detail. The engine fills the statistics that follow from the path.
//
// A new planner is a folder under planner/ with a Planner subclass and an
// options struct, plus one line in planner/assembly/builtin_planners.cc
// (and, for the API, its options message in the proto's oneof).
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
#include "planner/engine/limits.h"
#include "planner/engine/site.h"
#include "planner/plan/coverage_plan.h"
#include "planner/tour/robot_model.h"

namespace covplan {

// Options every planner shares. Validate() names fields as the API does
// ("robot.tool_width_m", "time_limit_s"), so the edge can pass its message on.
struct CommonOptions {
  RobotModel robot;
  double min_free_fraction = 0.5;
  // The search budget of a request that sets none, the same at every entry
  // point (covplan-server's --default_budget_s default, `covplan plan
  // --local`, `covplan compare`).
  static constexpr double kDefaultTimeLimitS = 2.0;
  double time_limit_s = kDefaultTimeLimitS;  // search budget (also bounded by `stop`)
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
