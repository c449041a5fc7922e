// The one transport-free planning engine: covplan-server and `covplan plan
// --local` both call it, so the two paths cannot drift apart. It validates
// the request (common options, the planner's options, regions and no-go
// zones against the map), builds or finds the per-map artifacts (grid,
// coverage area; the planner adds its own), runs the selected planner and
// fills the statistics that follow from the path. It also checks the
// result: no path segment may enter a no-go zone. With
// EngineLimits::plan_memory it remembers each plan in the cache and answers
// an identical request from it at once, or warm-starts a request that
// differs only in start/end pose or seed (plan_memory.h; the outcome is
// PlanStats::plan_source).
//
//   PlannerRegistry registry = BuiltinPlanners();  // planner/assembly
//   LocalArtifactCache cache;
//   PlanningEngine engine(&registry, &cache, EngineLimits{});
//   MapSource source{map_id, [&] { return LoadSite(...); }};
//   PlanRequest request; request.common.robot.tool_width_m = 0.8;
//   absl::StatusOr<CoveragePlan> plan = engine.Plan(source, request);
//
// Thread-safety: thread-safe when the cache is (the registry is read-only).
#ifndef COVPLAN_PLANNER_ENGINE_ENGINE_H_
#define COVPLAN_PLANNER_ENGINE_ENGINE_H_

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/energy/battery.h"
#include "planner/engine/artifact_cache.h"
#include "planner/engine/floor_artifact.h"
#include "planner/engine/planner.h"
#include "planner/engine/site.h"
#include "planner/geometry/area.h"
#include "planner/plan/coverage_plan.h"

namespace covplan {

// Planners by name, filled by the host's assembly (the shipped set:
// planner/assembly/builtin_planners.h); the engine knows none by name.
class PlannerRegistry {
 public:
  void Register(std::unique_ptr<Planner> planner);
  // The planner a request without a planner name gets (PlanRequest::planner
  // empty).
  void SetDefault(std::string name) { default_ = std::move(name); }
  const std::string& default_name() const { return default_; }
  const Planner* Find(std::string_view name) const;
  std::vector<std::string> Names() const;

 private:
  std::map<std::string, std::shared_ptr<const Planner>, std::less<>> planners_;
  std::string default_;
};

// Where a map comes from: its content id (all cache keys derive from it) and
// a loader that is called only when an artifact must be built.
struct MapSource {
  std::string map_id;
  std::function<absl::StatusOr<SiteMap>()> load;
};

struct PlanRequest {
  std::string planner;  // a registered name; empty: the registry's default
  CommonOptions common;
  std::shared_ptr<const PlannerOptions> options;  // null: the planner's defaults
  std::vector<PolygonInput> regions;
  std::vector<PolygonInput> no_go;
  // Battery-constrained tour (planner/energy): the plan is split into charge
  // cycles from and to the station. Unless given, robot.start and robot.end
  // default to the station.
  std::optional<BatteryOptions> battery;
  // With a remembered plan of an identical request (plan_memory.h): search
  // on from its tour within this request's budget and remember the better
  // of the two ("improved"), instead of returning it at once ("cache_hit").
  bool improve_remembered = false;
};

// A plan kept for GetPlan and later continuation: the plan, the request it
// answered and the coverage area (grid with barriers and obstacle pixels,
// zones) it was planned on.
struct RetainedPlan {
  std::string plan_id;
  std::string map_id;
  CoveragePlan plan;
  PlanRequest request;
  std::shared_ptr<const CoverageArea> area;
  size_t MemoryBytes() const { return sizeof(*this) + plan.MemoryBytes(); }
};

class RememberedPlan;   // plan_memory.h
struct PlanMemoryKeys;  // plan_memory.h

struct EngineResult {
  CoveragePlan plan;
  std::shared_ptr<const CoverageArea> area;
  // A cache hit (plan.stats.plan_source kCacheHit): the remembered entry
  // that answered. Entries are immutable, so the same entry is the same
  // answer; a server uses it to serve repeated hits with one reply.
  std::shared_ptr<const RememberedPlan> answered_by;
};

// A remembered answer found by PlanningEngine::Recall.
struct Recalled {
  // The answer, statistics filled; its plan has no grid (`area` holds it)
  // and is not copied: entries are immutable.
  std::shared_ptr<const RememberedPlan> entry;
  std::shared_ptr<const CoverageArea> area;
  double lookup_ms = 0.0;  // the look-up's own time
};

class PlanningEngine {
 public:
  PlanningEngine(const PlannerRegistry* registry, ArtifactCache* cache, EngineLimits limits)
      : registry_(registry), cache_(cache), limits_(limits) {}

  absl::StatusOr<EngineResult> Plan(const MapSource& source, const PlanRequest& request) const;
  // The plan Plan would answer at once from memory ("cache_hit"), found
  // without loading the map, building an artifact, searching or copying
  // the plan; it marks the entries used, as Plan does. nullopt when Plan
  // would have to do any of that: plan memory off, improve_remembered, an
  // artifact not cached, no remembered plan, or one that does not answer
  // this time limit. A request Plan would refuse is refused alike (or, when
  // the refusal needs the map, nullopt). Cheap enough for a server's
  // network thread.
  absl::StatusOr<std::optional<Recalled>> Recall(const MapSource& source,
                                                 const PlanRequest& request) const;
  // Plans `request` on a part of its coverage area: only the cells whose
  // `cover_mask` entry is non-zero (indexed like the area's grids, Grid::Index)
  // are swept; the robot may still drive anywhere on the drive grid. The
  // part's per-planner artifacts are keyed by the mask's content. Plan memory
  // is neither read nor written. InvalidArgument when the mask has the wrong
  // size or selects no cell to cover. For fleets (planner/fleet): one robot's
  // share of the site. A non-empty `drive_mask` (same indexing) also closes
  // every drive cell whose entry is zero (obstacles robots reported while
  // driving): the robot neither drives nor sweeps there.
  absl::StatusOr<EngineResult> PlanPart(const MapSource& source, const PlanRequest& request,
                                        const std::vector<uint8_t>& cover_mask,
                                        const std::vector<uint8_t>& drive_mask = {}) const;
  // Builds every per-map artifact `request` needs, without planning.
  absl::Status Prepare(const MapSource& source, const PlanRequest& request) const;
  // The reachable floor of the request's coverage area (floor_artifact.h),
  // from the cache or built and cached.
  absl::StatusOr<std::shared_ptr<const FloorArtifact>> FloorFor(const MapSource& source,
                                                                const PlanRequest& request) const;
  // The coverage area `request` plans on (validated like Plan), e.g. to
  // continue a plan the server did not retain.
  absl::StatusOr<std::shared_ptr<const CoverageArea>> AreaFor(const MapSource& source,
                                                              const PlanRequest& request) const;

  const PlannerRegistry& registry() const { return *registry_; }
  const EngineLimits& limits() const { return limits_; }

 private:
  struct Resolved {
    const Planner* planner = nullptr;
    std::shared_ptr<const PlannerOptions> options;
    AreaZones zones;
  };
  absl::StatusOr<Resolved> Resolve(const PlanRequest& request) const;
  enum class ArtifactUse { kBuild, kCachedOnly };
  // Finds (or with kBuild, builds) the grid and coverage area of `request`
  // and fills `ctx`. False with kCachedOnly when one is not cached.
  absl::StatusOr<bool> Setup(const MapSource& source, const PlanRequest& request,
                             const Resolved& resolved, ArtifactUse use, PlanContext* ctx,
                             bool* all_cached) const;
  // What Prepare, FloorFor and AreaFor work in: the request resolved and
  // every artifact of its area built (ctx points into the struct: not to be
  // moved once filled).
  struct Built {
    Resolved resolved;
    PlanContext ctx;
    bool all_cached = true;
  };
  absl::Status BuildArea(const MapSource& source, const PlanRequest& request, Built* out) const;
  PlanMemoryKeys MemoryKeys(const PlanRequest& request, const Resolved& resolved,
                            const PlanContext& ctx) const;
  // Path checks and path-derived statistics of a planner's result.
  absl::Status Finish(const PlanRequest& request, const Resolved& resolved,
                      const CoverageArea& area, bool all_cached, CoveragePlan* plan) const;

  const PlannerRegistry* registry_;
  ArtifactCache* cache_;
  EngineLimits limits_;
};

// Path length, turns and duration recomputed from waypoints alone (the
// robot turns in place to each waypoint's heading, then drives straight).
PlanStats ComputePathStats(const std::vector<Waypoint>& path, const RobotModel& robot);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_ENGINE_H_
