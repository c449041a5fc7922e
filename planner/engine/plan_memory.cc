#include "planner/engine/plan_memory.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace covplan {
namespace {

std::string PoseText(const std::optional<Pose2>& p) {
  return p.has_value() ? absl::StrFormat("%.17g,%.17g,%.17g", p->x, p->y, p->theta) : "none";
}

}  // namespace

PlanMemoryKeys PlanMemoryKeysFor(const ArtifactKey<CoverageArea>& area_key,
                                 std::string_view planner, const PlannerOptions& options,
                                 const CommonOptions& common,
                                 const std::optional<BatteryOptions>& battery) {
  const RobotModel& r = common.robot;
  std::string params = absl::StrFormat("planner=%s;options=%s;robot=%.17g,%.17g,%.17g,%.17g",
                                       planner, options.CacheText(), r.tool_width_m,
                                       r.max_speed_mps, r.acceleration_mps2, r.turn_rate_deg_s);
  if (battery.has_value()) {
    const BatteryOptions& b = *battery;
    absl::StrAppendFormat(&params, ";battery=%.17g,%s,%.17g,%.17g,%.17g,%.17g,%d,[%s]", b.capacity,
                          PoseText(b.station), b.reserve, b.energy.per_metre, b.energy.per_turn,
                          b.energy.per_second, b.interruptible_units ? 1 : 0,
                          absl::StrJoin(b.atomic_units, ","));
  } else {
    absl::StrAppend(&params, ";battery=none");
  }
  const auto base = area_key.Derive<RememberedPlan>("plan", params);
  PlanMemoryKeys keys;
  keys.tour = base.Derive<RememberedTour>("tour", "").text();
  keys.exact =
      base.Derive<RememberedPlan>(
              "exact", absl::StrFormat("seed=%d;threads=%d;start=%s;end=%s", common.seed,
                                       common.num_threads, PoseText(r.start), PoseText(r.end)))
          .text();
  return keys;
}

}  // namespace covplan
