#include "planner/plan/svg.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace covplan {
namespace {

// Emits one rect per horizontal run of pixels/cells for which pred(r, c).
template <typename Pred>
void AppendRuns(std::string* out, int rows, int cols, double x0, double y0, double size,
                const char* fill, Pred pred) {
  absl::StrAppend(out, "<g fill=\"", fill, "\" shape-rendering=\"crispEdges\">\n");
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols;) {
      if (!pred(r, c)) {
        ++c;
        continue;
      }
      int e = c;
      while (e + 1 < cols && pred(r, e + 1)) ++e;
      absl::StrAppendFormat(out, "<rect x=\"%.4f\" y=\"%.4f\" width=\"%.4f\" height=\"%.4f\"/>\n",
                            x0 + c * size, y0 + r * size, (e - c + 1) * size, size);
      c = e + 1;
    }
  }
  absl::StrAppend(out, "</g>\n");
}

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

// Transitions as dashed polylines.
void AppendTransitions(std::string* out, const CoveragePlan& plan, double s) {
  absl::StrAppendFormat(
      out,
      "<g stroke=\"#1f8a5b\" stroke-width=\"%.4f\" stroke-dasharray=\"%.4f %.4f\" fill=\"none\">\n",
      0.12 * s, 0.3 * s, 0.2 * s);
  for (size_t i = 1; i < plan.path.size(); ++i) {
    if (plan.path[i].kind != SegmentKind::kTransition) continue;
    absl::StrAppendFormat(out, "<line x1=\"%.4f\" y1=\"%.4f\" x2=\"%.4f\" y2=\"%.4f\"/>\n",
                          plan.path[i - 1].x, plan.path[i - 1].y, plan.path[i].x, plan.path[i].y);
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

// The start (filled green) and the end (red ring).
void AppendEnds(std::string* out, const CoveragePlan& plan, double s) {
  if (plan.path.empty()) return;
  const Waypoint& st = plan.path.front();
  const Waypoint& en = plan.path.back();
  absl::StrAppendFormat(out, "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"%.4f\" fill=\"#1aa33a\"/>\n",
                        st.x, st.y, 0.45 * s);
  absl::StrAppendFormat(out,
                        "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"%.4f\" fill=\"none\" "
                        "stroke=\"#d62728\" stroke-width=\"%.4f\"/>\n",
                        en.x, en.y, 0.6 * s, 0.15 * s);
}

// Legend above the map (not flipped), sized to fit the map's width `w`
// (sans-serif glyphs average about 0.56 em).
void AppendLegend(std::string* out, const CoveragePlan& plan, const SvgZones& zones, Point2 o,
                  double w, double legend_h) {
  const std::string summary =
      absl::StrFormat(" · %d ranks, %d turns, %.0f s", static_cast<int>(plan.stats.num_ranks),
                      static_cast<int>(plan.stats.num_turns), plan.stats.estimated_duration_s);
  std::string zone_legend;
  if (!zones.regions.empty()) zone_legend += " · <tspan fill=\"#1f5fa8\">regions</tspan>";
  if (!zones.no_go.empty()) zone_legend += " · <tspan fill=\"#a61e1e\">no-go zones</tspan>";
  constexpr int kLegendChars = 54;  // "horizontal ranks · vertical ranks · transitions"
  const double chars = kLegendChars + static_cast<double>(summary.size()) +
                       (zones.regions.empty() ? 0 : 10) + (zones.no_go.empty() ? 0 : 14);
  const double fs = std::min(0.45 * legend_h, (w - 0.4) / (0.56 * chars));
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
                        o.x + 0.2, -0.35 * legend_h, std::max(fs, 1e-3), sweeps_legend, summary,
                        zone_legend);
}

}  // namespace

void AppendPolygons(std::string* out, const std::vector<PolygonInput>& polygons, const char* fill,
                    const char* stroke, double stroke_width) {
  if (polygons.empty()) return;
  absl::StrAppendFormat(out,
                        "<g fill=\"%s\" fill-opacity=\"0.35\" fill-rule=\"evenodd\" stroke=\"%s\" "
                        "stroke-width=\"%.4f\">\n",
                        fill, stroke, stroke_width);
  for (const PolygonInput& p : polygons) {
    absl::StrAppend(out, "<path d=\"");
    auto ring = [&](const std::vector<Point2>& pts) {
      for (size_t i = 0; i < pts.size(); ++i) {
        absl::StrAppendFormat(out, "%s%.4f %.4f ", i == 0 ? "M" : "L", pts[i].x, pts[i].y);
      }
      absl::StrAppend(out, "Z ");
    };
    ring(p.outer);
    for (const auto& h : p.holes) ring(h);
    absl::StrAppend(out, "\"/>\n");
  }
  absl::StrAppend(out, "</g>\n");
}

std::string RenderPlanSvg(const CoveragePlan& plan, const OccupancyMap* map,
                          const SvgZones& zones) {
  const Grid& grid = *plan.grid;
  const double s = grid.cell_size();
  const Point2 o = grid.origin();
  double w = grid.cols() * s, h = grid.rows() * s;
  if (map) {
    w = std::max(w, map->width() * map->resolution());
    h = std::max(h, map->height() * map->resolution());
  }
  const double px_per_m = std::clamp(1600.0 / std::max(w, h), 2.0, 60.0);
  const double legend_h = 0.06 * std::max(w, h) + 1.0;
  std::string out;
  absl::StrAppendFormat(&out,
                        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                        "viewBox=\"%.4f %.4f %.4f %.4f\">\n",
                        w * px_per_m, (h + legend_h) * px_per_m, o.x, -legend_h, w, h + legend_h);
  absl::StrAppendFormat(
      &out, "<rect x=\"%.4f\" y=\"%.4f\" width=\"%.4f\" height=\"%.4f\" fill=\"#ffffff\"/>\n", o.x,
      -legend_h, w, h + legend_h);
  // Map frame: y up. Flip about the map's vertical extent.
  absl::StrAppendFormat(&out, "<g transform=\"matrix(1 0 0 -1 0 %.4f)\">\n", h + 2 * o.y);
  AppendRuns(&out, grid.rows(), grid.cols(), o.x, o.y, s, "#e3ecf7",
             [&](int r, int c) { return grid.IsFree(r, c); });
  if (map) {
    const Point2 mo = map->origin();
    const double res = map->resolution();
    AppendRuns(&out, map->height(), map->width(), mo.x, mo.y, res, "#b8b8b8",
               [&](int r, int c) { return map->at(r, c) == CellState::kUnknown; });
    AppendRuns(&out, map->height(), map->width(), mo.x, mo.y, res, "#202020",
               [&](int r, int c) { return map->at(r, c) == CellState::kOccupied; });
  }
  AppendPolygons(&out, zones.regions, "#4a90d9", "#1f5fa8", 0.08 * s);
  AppendPolygons(&out, zones.no_go, "#e03131", "#a61e1e", 0.08 * s);
  const std::vector<int> cycle_of = CycleOfWaypoint(plan);
  AppendCoverage(&out, plan, cycle_of, s);
  AppendTransitions(&out, plan, s);
  if (!plan.cycles.empty()) AppendStationLegs(&out, plan, cycle_of, s);
  AppendEnds(&out, plan, s);
  absl::StrAppend(&out, "</g>\n");
  AppendLegend(&out, plan, zones, o, w, legend_h);
  absl::StrAppend(&out, "</svg>\n");
  return out;
}

}  // namespace covplan
