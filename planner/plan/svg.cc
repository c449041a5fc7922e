#include "planner/plan/svg.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/plan/floor_measure.h"
#include "planner/plan/svg_layers.h"

namespace covplan {
namespace {

using svg_internal::AppendEnds;
using svg_internal::AppendRuns;
using svg_internal::AppendSegments;
using svg_internal::AppendSite;
using svg_internal::AppendSvgClose;
using svg_internal::AppendSvgOpen;
using svg_internal::LegendFontSize;
using svg_internal::SvgFrame;
using svg_internal::SvgFrameOf;

// The reachable floor the path misses.
constexpr const char* kMissedFill = "#ff2d95";

// Charge cycle colours, in cycle order (repeating after ten).
constexpr const char* kCycleColours[] = {"#e6194b", "#3cb44b", "#4363d8", "#f58231", "#911eb4",
                                         "#42d4f4", "#f032e6", "#9a6324", "#469990", "#808000"};

// The charge cycle each waypoint's segment belongs to, or -1.
std::vector<int> CycleOfWaypoint(const CoveragePlan& plan) {
  std::vector<int> cycle_of(plan.path.size(), -1);
  for (size_t c = 0; c < plan.cycles.size(); ++c) {
    for (int w = plan.cycles[c].first_waypoint + 1; w <= plan.cycles[c].last_waypoint; ++w) {
      if (w >= 0 && w < static_cast<int>(plan.path.size())) cycle_of[w] = static_cast<int>(c);
    }
  }
  return cycle_of;
}

// Coverage segments, coloured by direction (horizontal / vertical sweeps),
// or, in battery plans, by charge cycle.
void AppendCoverage(std::string* out, const CoveragePlan& plan, const std::vector<int>& cycle_of,
                    double s) {
  const double stroke = 0.55 * s;
  absl::StrAppendFormat(out, "<g stroke-width=\"%.4f\" stroke-linecap=\"round\" fill=\"none\">\n",
                        stroke);
  for (size_t i = 1; i < plan.path.size(); ++i) {
    const Waypoint& a = plan.path[i - 1];
    const Waypoint& b = plan.path[i];
    if (b.kind != SegmentKind::kCoverage) continue;
    const bool horizontal = std::abs(b.y - a.y) <= std::abs(b.x - a.x);
    const char* color = cycle_of[i] >= 0 ? kCycleColours[cycle_of[i] % 10]
                        : horizontal     ? "#f08c2e"
                                         : "#8e44ad";
    absl::StrAppendFormat(out,
                          "<line x1=\"%.4f\" y1=\"%.4f\" x2=\"%.4f\" y2=\"%.4f\" stroke=\"%s\" "
                          "stroke-opacity=\"0.8\"/>\n",
                          a.x, a.y, b.x, b.y, color);
  }
  absl::StrAppend(out, "</g>\n");
}

// Station legs dotted, in their charge cycle's colour.
void AppendStationLegs(std::string* out, const CoveragePlan& plan, const std::vector<int>& cycle_of,
                       double s) {
  absl::StrAppendFormat(out,
                        "<g stroke-width=\"%.4f\" stroke-dasharray=\"%.4f %.4f\" fill=\"none\">\n",
                        0.15 * s, 0.1 * s, 0.25 * s);
  for (size_t i = 1; i < plan.path.size(); ++i) {
    const SegmentKind k = plan.path[i].kind;
    if ((k != SegmentKind::kToStation && k != SegmentKind::kFromStation) || cycle_of[i] < 0)
      continue;
    absl::StrAppendFormat(out,
                          "<line x1=\"%.4f\" y1=\"%.4f\" x2=\"%.4f\" y2=\"%.4f\" stroke=\"%s\"/>\n",
                          plan.path[i - 1].x, plan.path[i - 1].y, plan.path[i].x, plan.path[i].y,
                          kCycleColours[cycle_of[i] % 10]);
  }
  absl::StrAppend(out, "</g>\n");
}

// The reachable floor the path misses (floor_measure.h), in the map's
// pixels, drawn over the site; its area in m2 (0: nothing missed, or no map).
double AppendMissedFloor(std::string* out, const CoveragePlan& plan, const OccupancyMap* map,
                         const SvgZones& zones) {
  if (map == nullptr || plan.grid == nullptr) return 0.0;
  auto area = [](const std::vector<PolygonInput>& p, const char* field) -> std::optional<Area> {
    if (p.empty()) return std::nullopt;
    absl::StatusOr<Area> a = Area::Create(p, field);
    return a.ok() ? std::optional<Area>(*std::move(a)) : std::nullopt;
  };
  const std::optional<Area> no_go = area(zones.no_go, "no_go");
  const std::optional<Area> regions = area(zones.regions, "regions");
  const FloorReach reach =
      ComputeFloorReach(*map, *plan.grid, no_go ? &*no_go : nullptr, regions ? &*regions : nullptr);
  const FloorMeasure m = MeasureFloor(reach, plan.path, /*keep_missed=*/true);
  if (m.missed.empty()) return 0.0;
  const int64_t w = reach.width;
  AppendRuns(out, static_cast<int>(reach.height), static_cast<int>(w), reach.origin.x,
             reach.origin.y, reach.pixel_m, kMissedFill,
             [&](int r, int c) { return m.missed[static_cast<size_t>(r * w + c)] != 0; });
  return m.missed_reachable_m2;
}

// Legend above the map (not flipped), sized to fit the map's width
// (sans-serif glyphs average about 0.56 em).
void AppendLegend(std::string* out, const CoveragePlan& plan, const SvgZones& zones,
                  double missed_m2, const SvgFrame& f) {
  const std::string summary =
      absl::StrFormat(" · %d ranks, %d turns, %.0f s", static_cast<int>(plan.stats.num_ranks),
                      static_cast<int>(plan.stats.num_turns), plan.stats.estimated_duration_s);
  std::string zone_legend;
  if (!zones.regions.empty()) zone_legend += " · <tspan fill=\"#1f5fa8\">regions</tspan>";
  if (!zones.no_go.empty()) zone_legend += " · <tspan fill=\"#a61e1e\">no-go zones</tspan>";
  if (missed_m2 > 0.0) {
    zone_legend += absl::StrFormat(" · <tspan fill=\"%s\">missed floor %.1f m²</tspan>",
                                   kMissedFill, missed_m2);
  }
  constexpr int kLegendChars = 54;  // "horizontal ranks · vertical ranks · transitions"
  const double chars = kLegendChars + static_cast<double>(summary.size()) +
                       (zones.regions.empty() ? 0 : 10) + (zones.no_go.empty() ? 0 : 14) +
                       (missed_m2 > 0.0 ? 24 : 0);
  const double fs = LegendFontSize(f, chars);
  const std::string sweeps_legend =
      plan.cycles.empty()
          ? std::string(
                "<tspan fill=\"#f08c2e\">horizontal ranks</tspan> · "
                "<tspan fill=\"#8e44ad\">vertical ranks</tspan>")
          : absl::StrFormat(
                "<tspan fill=\"#e6194b\">%d charge cycles</tspan> (colours; station legs dotted)",
                static_cast<int>(plan.cycles.size()));
  absl::StrAppendFormat(out,
                        "<text x=\"%.4f\" y=\"%.4f\" font-family=\"sans-serif\" font-size=\"%.4f\">"
                        "%s · <tspan fill=\"#1f8a5b\">transitions</tspan>%s%s</text>\n",
                        f.origin.x + 0.2, -0.35 * f.legend_h, fs, sweeps_legend, summary,
                        zone_legend);
}

}  // namespace

std::string RenderPlanSvg(const CoveragePlan& plan, const OccupancyMap* map,
                          const SvgZones& zones) {
  const Grid& grid = *plan.grid;
  const SvgFrame f = SvgFrameOf(grid, map, 1);
  const double s = f.cell;
  std::string out;
  AppendSvgOpen(&out, f);
  AppendSite(&out, grid, map, zones);
  const double missed_m2 = AppendMissedFloor(&out, plan, map, zones);
  const std::vector<int> cycle_of = CycleOfWaypoint(plan);
  AppendCoverage(&out, plan, cycle_of, s);
  AppendSegments(&out, plan.path, {SegmentKind::kTransition},
                 absl::StrFormat("stroke=\"#1f8a5b\" stroke-width=\"%.4f\" "
                                 "stroke-dasharray=\"%.4f %.4f\" fill=\"none\"",
                                 0.12 * s, 0.3 * s, 0.2 * s));
  if (!plan.cycles.empty()) AppendStationLegs(&out, plan, cycle_of, s);
  AppendEnds(&out, plan.path, s, "#1aa33a", "", "#d62728");
  std::string legend;
  AppendLegend(&legend, plan, zones, missed_m2, f);
  AppendSvgClose(&out, legend);
  return out;
}

}  // namespace covplan
