#include "planner/engine/engine.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/energy/charge_cycles.h"
#include "planner/engine/floor_artifact.h"
#include "planner/engine/plan_memory.h"
#include "planner/tour/path_timing.h"
#include "planner/tour/tour_model.h"

namespace covplan {
namespace {

// InvalidArgument when a zone polygon's outer ring misses the map entirely.
absl::Status CheckInsideMap(const std::vector<PolygonInput>& polygons, const char* field, Point2 lo,
                            Point2 hi) {
  for (size_t i = 0; i < polygons.size(); ++i) {
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (const Point2& p : polygons[i].outer) {
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x),
      y1 = std::max(y1, p.y);
    }
    if (x1 <= lo.x || y1 <= lo.y || x0 >= hi.x || y0 >= hi.y) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s[%d] lies outside the map: its bounds (%.3f, %.3f)..(%.3f, %.3f) miss the map's "
          "(%.3f, %.3f)..(%.3f, %.3f)",
          field, i, x0, y0, x1, y1, lo.x, lo.y, hi.x, hi.y));
    }
  }
  return absl::OkStatus();
}

// Trials a new start pose's warm start spends (OrdererOptions::warm_trials):
// none. The remembered cycle, cut at its best place for the new start and
// locally optimised, is as good as a cold search on the shipped maps
// (docs/benchmarks.md §12) at a small fraction of its time.
constexpr int kWarmStartTrials = 0;

}  // namespace

absl::Status CommonOptions::Validate() const {
  RETURN_IF_ERROR(robot.Validate());
  if (!std::isfinite(time_limit_s) || time_limit_s < 0.0 || time_limit_s > kMaxTimeLimitS) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "time_limit_s must be in [0, %g] seconds, got %g", kMaxTimeLimitS, time_limit_s));
  }
  if (num_threads < 1 || num_threads > 256) {
    return absl::InvalidArgumentError(
        absl::StrFormat("num_threads must be in [1, 256], got %d", num_threads));
  }
  if (!std::isfinite(min_free_fraction) || min_free_fraction < 0.0 || min_free_fraction >= 1.0) {
    return absl::InvalidArgumentError(
        absl::StrFormat("min_free_fraction must be in [0, 1), got %g", min_free_fraction));
  }
  return absl::OkStatus();
}

void PlannerRegistry::Register(std::unique_ptr<Planner> planner) {
  std::string name(planner->name());
  planners_[name] = std::shared_ptr<const Planner>(std::move(planner));
}

const Planner* PlannerRegistry::Find(std::string_view name) const {
  auto it = planners_.find(name);
  return it == planners_.end() ? nullptr : it->second.get();
}

std::vector<std::string> PlannerRegistry::Names() const {
  std::vector<std::string> names;
  for (const auto& [name, planner] : planners_) names.push_back(name);
  return names;
}

absl::StatusOr<PlanningEngine::Resolved> PlanningEngine::Resolve(const PlanRequest& request) const {
  Resolved r;
  r.planner =
      registry_->Find(request.planner.empty() ? registry_->default_name() : request.planner);
  if (r.planner == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrFormat("planner: unknown planner '%s'; registered: %s", request.planner,
                        absl::StrJoin(registry_->Names(), ", ")));
  }
  RETURN_IF_ERROR(request.common.Validate());
  if (request.battery.has_value()) RETURN_IF_ERROR(request.battery->Validate());
  r.options = request.options != nullptr ? request.options : r.planner->DefaultOptions();
  RETURN_IF_ERROR(r.planner->CheckOptions(*r.options));
  AreaLimits area_limits;
  area_limits.max_vertices = limits_.max_area_vertices;
  if (!request.regions.empty()) {
    ASSIGN_OR_RETURN(Area regions, Area::Create(request.regions, "regions", area_limits));
    r.zones.regions = std::make_shared<const Area>(std::move(regions));
  }
  if (!request.no_go.empty()) {
    ASSIGN_OR_RETURN(Area no_go, Area::Create(request.no_go, "no_go", area_limits));
    r.zones.no_go = std::make_shared<const Area>(std::move(no_go));
    for (auto [pose, name] : {std::pair{&request.common.robot.start, "robot.start"},
                              std::pair{&request.common.robot.end, "robot.end"}}) {
      if (pose->has_value() && r.zones.no_go->Contains({(*pose)->x, (*pose)->y})) {
        return absl::InvalidArgumentError(
            absl::StrFormat("%s (%.3f, %.3f) lies in a no-go zone", name, (*pose)->x, (*pose)->y));
      }
    }
    if (request.battery.has_value() &&
        r.zones.no_go->Contains({request.battery->station.x, request.battery->station.y})) {
      return absl::InvalidArgumentError(
          absl::StrFormat("battery.station (%.3f, %.3f) lies in a no-go zone",
                          request.battery->station.x, request.battery->station.y));
    }
  }
  return r;
}

absl::StatusOr<bool> PlanningEngine::Setup(const MapSource& source, const PlanRequest& request,
                                           const Resolved& resolved, ArtifactUse use,
                                           PlanContext* ctx, bool* all_cached) const {
  const CommonOptions& common = request.common;
  GridOptions grid_options;
  grid_options.cell_size = common.robot.tool_width_m;
  grid_options.min_free_fraction = common.min_free_fraction;
  grid_options.max_cells = limits_.max_grid_cells;
  const auto grid_key = ArtifactKey<GridArtifact>::Root(
      source.map_id, "grid",
      absl::StrFormat("cell=%.9g;minfree=%.9g", grid_options.cell_size,
                      grid_options.min_free_fraction));
  bool hit = false;
  std::shared_ptr<const GridArtifact> grid;
  if (use == ArtifactUse::kCachedOnly) {
    grid = std::dynamic_pointer_cast<const GridArtifact>(cache_->Find(grid_key.text()));
    if (grid == nullptr) return false;
  } else {
    ASSIGN_OR_RETURN(
        grid, GetOrBuild(
                  *cache_, grid_key, common.stop,
                  [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const GridArtifact>> {
                    if (!source.load) return absl::InternalError("map source without loader");
                    ASSIGN_OR_RETURN(SiteMap site, source.load());
                    return BuildGridArtifact(site, grid_options);
                  },
                  &hit));
    *all_cached = *all_cached && hit;
  }
  const Grid& g = *grid->grid;
  const Point2 lo = g.origin();
  const Point2 hi{lo.x + g.cols() * g.cell_size(), lo.y + g.rows() * g.cell_size()};
  RETURN_IF_ERROR(CheckInsideMap(request.regions, "regions", lo, hi));
  RETURN_IF_ERROR(CheckInsideMap(request.no_go, "no_go", lo, hi));
  const auto area_key = grid_key.Derive<CoverageArea>("area", resolved.zones.CacheText());
  std::shared_ptr<const CoverageArea> area;
  if (use == ArtifactUse::kCachedOnly) {
    area = std::dynamic_pointer_cast<const CoverageArea>(cache_->Find(area_key.text()));
    if (area == nullptr) return false;
  } else {
    ASSIGN_OR_RETURN(area, GetOrBuild(
                               *cache_, area_key, common.stop,
                               [&](const StopToken&) {
                                 return BuildCoverageArea(*grid, resolved.zones,
                                                          common.min_free_fraction);
                               },
                               &hit));
    *all_cached = *all_cached && hit;
  }
  ctx->common = &request.common;
  ctx->options = resolved.options.get();
  ctx->area = std::move(area);
  ctx->area_key = area_key;
  ctx->cache = cache_;
  ctx->limits = limits_;
  ctx->all_cached = all_cached;
  return true;
}

absl::Status PlanningEngine::BuildArea(const MapSource& source, const PlanRequest& request,
                                       Built* out) const {
  ASSIGN_OR_RETURN(out->resolved, Resolve(request));
  return Setup(source, request, out->resolved, ArtifactUse::kBuild, &out->ctx, &out->all_cached)
      .status();
}

absl::Status PlanningEngine::Prepare(const MapSource& source, const PlanRequest& request) const {
  Built built;
  RETURN_IF_ERROR(BuildArea(source, request, &built));
  RETURN_IF_ERROR(covplan::FloorFor(built.ctx).status());
  return built.resolved.planner->Prepare(built.ctx);
}

absl::StatusOr<std::shared_ptr<const FloorArtifact>> PlanningEngine::FloorFor(
    const MapSource& source, const PlanRequest& request) const {
  Built built;
  RETURN_IF_ERROR(BuildArea(source, request, &built));
  return covplan::FloorFor(built.ctx);
}

absl::StatusOr<std::shared_ptr<const CoverageArea>> PlanningEngine::AreaFor(
    const MapSource& source, const PlanRequest& request) const {
  Built built;
  RETURN_IF_ERROR(BuildArea(source, request, &built));
  return built.ctx.area;
}

absl::Status PlanningEngine::Finish(const PlanRequest& request, const Resolved& resolved,
                                    const CoverageArea& area, bool all_cached,
                                    CoveragePlan* plan) const {
  // The engine's own check: no segment may enter a no-go zone's interior.
  if (resolved.zones.has_no_go()) {
    for (size_t i = 1; i < plan->path.size(); ++i) {
      const Waypoint& a = plan->path[i - 1];
      const Waypoint& b = plan->path[i];
      if (resolved.zones.no_go->SegmentLengthInInterior({a.x, a.y}, {b.x, b.y}) <= 1e-9) continue;
      const bool from_start = i <= 2 && request.common.robot.start.has_value();
      const bool to_end = i + 2 >= plan->path.size() && request.common.robot.end.has_value();
      const bool station_leg = request.battery.has_value() && (b.kind == SegmentKind::kToStation ||
                                                               b.kind == SegmentKind::kFromStation);
      if (station_leg) {
        return absl::InvalidArgumentError(
            absl::StrFormat("battery.station: the move between (%.3f, %.3f) and (%.3f, %.3f) near "
                            "the station would "
                            "cross a no-go zone; move the station away from the zone",
                            a.x, a.y, b.x, b.y));
      }
      if (from_start || to_end) {
        return absl::InvalidArgumentError(
            absl::StrFormat("%s: the move between (%.3f, %.3f) and the grid at (%.3f, %.3f) would "
                            "cross a no-go zone",
                            from_start ? "robot.start" : "robot.end", a.x, a.y, b.x, b.y));
      }
      return absl::InternalError(absl::StrFormat(
          "planner '%s' produced a segment through a no-go zone at (%.3f, %.3f)-(%.3f, %.3f)",
          resolved.planner->name(), a.x, a.y, b.x, b.y));
    }
  }

  PlanStats& s = plan->stats;
  const PlanStats path_stats = ComputePathStats(plan->path, request.common.robot);
  s.num_turns = path_stats.num_turns;
  s.coverage_length_m = path_stats.coverage_length_m;
  s.transition_length_m = path_stats.transition_length_m;
  s.estimated_duration_s = path_stats.estimated_duration_s;
  s.turning_time_s = path_stats.turning_time_s;
  s.grid_rows = area.drive->rows();
  s.grid_cols = area.drive->cols();
  s.free_cells = area.cover_cells;
  std::vector<uint8_t> swept(static_cast<size_t>(area.drive->size()), 0);
  s.covered_cells = 0;
  for (const CoverageSweep& sweep : plan->sweeps) {
    for (const CellIndex& c : sweep.cells) {
      if (!area.drive->InBounds(c.row, c.col)) continue;
      uint8_t& bit = swept[area.drive->Index(c.row, c.col)];
      s.covered_cells += bit == 0;
      bit = 1;
    }
  }
  s.unreachable_free_cells = area.unreachable_cells;
  s.no_go_cells = area.no_go_cells;
  s.map_free_area_m2 = area.map_free_area_m2;
  s.covered_free_area_ratio = area.covered_free_area_ratio;
  s.grid_ms = area.grid_ms;
  s.planning_ms = s.grid_ms + s.partition_ms + s.transitions_ms + s.tour_ms;
  s.decomposition_cached = all_cached;
  const TerminationLimit limit = plan->termination.limit;
  s.tour_cut_short = limit == TerminationLimit::kDeadline || limit == TerminationLimit::kCancelled;
  return absl::OkStatus();
}

namespace {

// A battery tour starts and ends at the station unless told otherwise.
PlanRequest WithStationPoses(const PlanRequest& original) {
  PlanRequest request = original;
  if (request.battery.has_value()) {
    if (!request.common.robot.start) request.common.robot.start = request.battery->station;
    if (!request.common.robot.end) request.common.robot.end = request.battery->station;
  }
  return request;
}

// True when `remembered` is the answer to `request` without a search.
bool AnswersAtOnce(const RememberedPlan* remembered, const PlanRequest& request) {
  return remembered != nullptr && !request.improve_remembered &&
         remembered->Answers(request.common.time_limit_s);
}

}  // namespace

PlanMemoryKeys PlanningEngine::MemoryKeys(const PlanRequest& request, const Resolved& resolved,
                                          const PlanContext& ctx) const {
  return PlanMemoryKeysFor(ctx.area_key, resolved.planner->name(), *resolved.options,
                           request.common, request.battery);
}

absl::StatusOr<std::optional<Recalled>> PlanningEngine::Recall(const MapSource& source,
                                                               const PlanRequest& original) const {
  if (!limits_.plan_memory || original.improve_remembered) return std::nullopt;
  const absl::Time t0 = absl::Now();
  ASSIGN_OR_RETURN(Resolved resolved, Resolve(original));
  const PlanRequest request = WithStationPoses(original);
  PlanContext ctx;
  bool all_cached = true;
  ASSIGN_OR_RETURN(const bool cached,
                   Setup(source, request, resolved, ArtifactUse::kCachedOnly, &ctx, &all_cached));
  if (!cached) return std::nullopt;
  if (request.battery.has_value())
    RETURN_IF_ERROR(CheckStation(*ctx.area->drive, *request.battery));
  std::shared_ptr<const RememberedPlan> entry =
      FindRemembered<RememberedPlan>(*cache_, MemoryKeys(request, resolved, ctx).exact);
  if (!AnswersAtOnce(entry.get(), request)) return std::nullopt;
  return Recalled{std::move(entry), std::move(ctx.area),
                  absl::ToDoubleMilliseconds(absl::Now() - t0)};
}

absl::StatusOr<EngineResult> PlanningEngine::Plan(const MapSource& source,
                                                  const PlanRequest& original) const {
  const absl::Time t0 = absl::Now();
  ASSIGN_OR_RETURN(Resolved resolved, Resolve(original));
  PlanRequest request = WithStationPoses(original);
  PlanContext ctx;
  bool all_cached = true;
  RETURN_IF_ERROR(
      Setup(source, request, resolved, ArtifactUse::kBuild, &ctx, &all_cached).status());
  if (request.battery.has_value())
    RETURN_IF_ERROR(CheckStation(*ctx.area->drive, *request.battery));

  // Remembered plans (plan_memory.h).
  std::optional<PlanMemoryKeys> keys;
  std::shared_ptr<const RememberedPlan> remembered;
  std::shared_ptr<const RememberedTour> remembered_tour;
  PlanOrigin plan_source = PlanOrigin::kCold;
  if (limits_.plan_memory) {
    keys = MemoryKeys(request, resolved, ctx);
    remembered = FindRemembered<RememberedPlan>(*cache_, keys->exact);
    if (AnswersAtOnce(remembered.get(), request)) {
      // Copied outside the cache's lock; the entry itself stays shared.
      EngineResult hit{remembered->plan, ctx.area, remembered};
      hit.plan.grid = ctx.area->drive;
      PlanStats& s = hit.plan.stats;
      s.plan_source = PlanOrigin::kCacheHit;
      s.tour_ms = 0.0;
      s.floor_ms = 0.0;  // measured when it was planned
      s.decomposition_cached = all_cached;
      s.planning_ms = absl::ToDoubleMilliseconds(absl::Now() - t0);
      return hit;
    }
    const bool warm = resolved.planner->SupportsWarmStart(*resolved.options);
    if (remembered != nullptr) {
      // Search on: from the remembered tour where the planner can start from
      // one (the dense GTSP), else a fresh search; the better plan is kept.
      if (warm && !remembered->plan.tour_vertices.empty()) {
        ctx.warm_tour = &remembered->plan.tour_vertices;
        ctx.warm_trials = OrdererOptions::kEffortTrials;  // all warm
      }
      // Each further improvement run searches with seeds of its own.
      request.common.seed +=
          0x9E3779B97F4A7C15ull * static_cast<uint64_t>(remembered->generation + 1);
      plan_source = PlanOrigin::kImproved;
    } else if (warm &&
               (remembered_tour = FindRemembered<RememberedTour>(*cache_, keys->tour)) != nullptr) {
      ctx.warm_tour = &remembered_tour->vertices;
      ctx.warm_trials = kWarmStartTrials;
      plan_source = PlanOrigin::kWarmStart;
    }
  }

  ASSIGN_OR_RETURN(CoveragePlan plan, resolved.planner->Plan(ctx));
  request.common.seed = original.common.seed;
  const CoverageArea& area = *ctx.area;
  plan.planner = std::string(resolved.planner->name());
  if (request.battery.has_value()) {
    const absl::Time t = absl::Now();
    ASSIGN_OR_RETURN(plan, SplitIntoChargeCycles(plan, *area.drive, *request.battery,
                                                 request.common.robot, request.common.stop));
    plan.stats.tour_ms +=
        absl::ToDoubleMilliseconds(absl::Now() - t);  // the split is part of the tour
  }
  RETURN_IF_ERROR(Finish(request, resolved, area, all_cached, &plan));
  RETURN_IF_ERROR(MeasurePlanFloor(ctx, &plan));
  plan.stats.planning_ms += plan.stats.floor_ms;
  plan.stats.plan_source = plan_source;

  if (keys.has_value()) {
    int generation = 0;
    if (plan_source == PlanOrigin::kImproved) {
      generation = remembered->generation + 1;
      if (remembered->plan.stats.estimated_duration_s < plan.stats.estimated_duration_s) {
        // The search found nothing better: answer (and keep) the remembered plan.
        // Its statistics and termination still tell how this search went.
        const PlanStats fresh = plan.stats;
        const Termination termination = plan.termination;
        plan = remembered->plan;
        plan.grid = area.drive;
        plan.termination = termination;
        plan.stats.plan_source = PlanOrigin::kImproved;
        plan.stats.tour_ms = fresh.tour_ms;
        plan.stats.floor_ms = fresh.floor_ms;
        plan.stats.planning_ms = fresh.planning_ms;
        plan.stats.decomposition_cached = fresh.decomposition_cached;
        plan.stats.tour_cut_short = fresh.tour_cut_short;
      }
    }
    // The tour to warm-start from comes from full searches only, so that
    // warm starts (a local step for one start pose) cannot wear it down.
    if (!plan.tour_vertices.empty() && plan_source != PlanOrigin::kWarmStart) {
      auto tour = std::make_shared<RememberedTour>();
      tour->vertices = plan.tour_vertices;
      cache_->Put(keys->tour, std::move(tour));
    }
    // A plan the caller's deadline or cancellation cut short is not what
    // this request would get with its time: only its tour is remembered.
    if (!plan.stats.tour_cut_short) {
      auto entry = std::make_shared<RememberedPlan>();
      entry->plan = plan;
      entry->plan.grid = nullptr;  // held by the coverage area
      entry->generation = generation;
      entry->time_limit_s = std::max(request.common.time_limit_s,
                                     remembered != nullptr ? remembered->time_limit_s : 0.0);
      cache_->Put(keys->exact, std::move(entry));
    }
  }
  return EngineResult{std::move(plan), ctx.area, nullptr};
}

absl::StatusOr<EngineResult> PlanningEngine::PlanPart(
    const MapSource& source, const PlanRequest& original, const std::vector<uint8_t>& cover_mask,
    const std::vector<uint8_t>& drive_mask) const {
  ASSIGN_OR_RETURN(Resolved resolved, Resolve(original));
  const PlanRequest request = WithStationPoses(original);
  PlanContext ctx;
  bool all_cached = true;
  RETURN_IF_ERROR(
      Setup(source, request, resolved, ArtifactUse::kBuild, &ctx, &all_cached).status());
  if (request.battery.has_value())
    RETURN_IF_ERROR(CheckStation(*ctx.area->drive, *request.battery));
  const CoverageArea& whole = *ctx.area;
  if (static_cast<int64_t>(cover_mask.size()) != whole.cover->size()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "cover mask has %d entries, the grid %d cells", cover_mask.size(), whole.cover->size()));
  }
  if (!drive_mask.empty() && drive_mask.size() != cover_mask.size()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "drive mask has %d entries, the grid %d cells", drive_mask.size(), whole.cover->size()));
  }
  // FNV-1a over the selected cell indices, then over the closed ones.
  uint64_t digest = 1469598103934665603ull;
  auto hash = [&digest](size_t i) {
    for (uint64_t v = i + 1; v != 0; v >>= 8) digest = (digest ^ (v & 0xff)) * 1099511628211ull;
  };
  std::vector<uint8_t> drive = whole.drive->free_flags();
  int64_t closed = 0;
  for (size_t i = 0; i < drive.size() && !drive_mask.empty(); ++i) {
    if (drive[i] == 0 || drive_mask[i] != 0) continue;
    drive[i] = 0;
    ++closed;
  }
  std::vector<uint8_t> flags = whole.cover->free_flags();
  int64_t cells = 0;
  for (size_t i = 0; i < flags.size(); ++i) {
    flags[i] = flags[i] != 0 && cover_mask[i] != 0 && drive[i] != 0;
    if (flags[i] == 0) continue;
    ++cells;
    hash(i);
  }
  if (cells == 0) return absl::InvalidArgumentError("cover mask selects no cell to cover");
  auto part = std::make_shared<CoverageArea>(whole);
  part->cover = std::make_shared<const Grid>(whole.cover->WithFreeFlags(std::move(flags)));
  part->cover_cells = cells;
  std::string key = absl::StrFormat("%d", cells);
  if (closed > 0) {
    for (size_t i = 0; i < drive.size(); ++i) {
      if (whole.drive->free_flags()[i] != 0 && drive[i] == 0) hash(i);
    }
    part->drive = std::make_shared<const Grid>(whole.drive->WithFreeFlags(std::move(drive)));
    key = absl::StrFormat("%d-%d", cells, closed);
  }
  ctx.area_key =
      ctx.area_key.Derive<CoverageArea>("part", absl::StrFormat("%s:%016x", key, digest));
  ctx.area = part;
  ASSIGN_OR_RETURN(CoveragePlan plan, resolved.planner->Plan(ctx));
  plan.planner = std::string(resolved.planner->name());
  if (request.battery.has_value()) {
    const absl::Time t = absl::Now();
    ASSIGN_OR_RETURN(plan, SplitIntoChargeCycles(plan, *part->drive, *request.battery,
                                                 request.common.robot, request.common.stop));
    plan.stats.tour_ms += absl::ToDoubleMilliseconds(absl::Now() - t);
  }
  RETURN_IF_ERROR(Finish(request, resolved, *part, all_cached, &plan));
  return EngineResult{std::move(plan), std::move(part), nullptr};
}

PlanStats ComputePathStats(const std::vector<Waypoint>& path, const RobotModel& robot) {
  PlanStats s;
  if (path.empty()) return s;
  double heading = path[0].theta;
  for (size_t i = 1; i < path.size(); ++i) {
    const Waypoint& a = path[i - 1];
    const Waypoint& b = path[i];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const double change = HeadingChange(heading, b.theta);
    if (change > kTurnEpsilonRad) {
      ++s.num_turns;
      s.turning_time_s += robot.TurnTime(change);
    }
    heading = b.theta;
    s.estimated_duration_s += robot.StraightTime(len);
    (b.kind == SegmentKind::kCoverage ? s.coverage_length_m : s.transition_length_m) += len;
  }
  s.estimated_duration_s += s.turning_time_s;
  return s;
}

}  // namespace covplan
