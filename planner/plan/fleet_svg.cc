#include "planner/plan/fleet_svg.h"

#include <algorithm>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
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

// Distinguishable on the light site background (no yellow or cyan).
constexpr const char* kColours[kFleetSvgColours] = {"#e6194b", "#3cb44b", "#4363d8", "#f58231",
                                                    "#911eb4", "#008080", "#f032e6", "#9a6324"};
// Robots per legend row: at least this many, more while a row of them is no
// wider than the key row.
constexpr size_t kMinRobotsPerLegendRow = 4;

std::string XmlEscaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The cells each robot's coverage sweeps, tinted in its colour.
void AppendShares(std::string* out, const std::vector<FleetSvgRobot>& robots, const Grid& grid) {
  std::vector<int> owner(static_cast<size_t>(grid.size()), -1);
  for (size_t i = 0; i < robots.size(); ++i) {
    if (robots[i].plan == nullptr) continue;
    for (const CoverageSweep& sweep : robots[i].plan->sweeps) {
      for (const CellIndex& c : sweep.cells) {
        if (grid.InBounds(c.row, c.col)) owner[grid.Index(c.row, c.col)] = static_cast<int>(i);
      }
    }
  }
  absl::StrAppend(out, "<g fill-opacity=\"0.2\">\n");
  for (size_t i = 0; i < robots.size(); ++i) {
    AppendRuns(out, grid.rows(), grid.cols(), grid.origin().x, grid.origin().y, grid.cell_size(),
               FleetSvgColour(i),
               [&](int r, int c) { return owner[grid.Index(r, c)] == static_cast<int>(i); });
  }
  absl::StrAppend(out, "</g>\n");
}

// One robot's path: coverage solid, transitions dashed, station legs dotted,
// the start a disc outlined in black, the end a ring.
void AppendRobot(std::string* out, const CoveragePlan& plan, const char* colour, double s) {
  AppendSegments(out, plan.path, {SegmentKind::kCoverage},
                 absl::StrFormat("stroke=\"%s\" stroke-width=\"%.4f\" stroke-linecap=\"round\" "
                                 "stroke-opacity=\"0.85\" fill=\"none\"",
                                 colour, 0.45 * s));
  AppendSegments(out, plan.path, {SegmentKind::kTransition},
                 absl::StrFormat("stroke=\"%s\" stroke-width=\"%.4f\" "
                                 "stroke-dasharray=\"%.4f %.4f\" fill=\"none\"",
                                 colour, 0.12 * s, 0.3 * s, 0.2 * s));
  if (!plan.cycles.empty()) {
    AppendSegments(out, plan.path, {SegmentKind::kToStation, SegmentKind::kFromStation},
                   absl::StrFormat("stroke=\"%s\" stroke-width=\"%.4f\" "
                                   "stroke-dasharray=\"%.4f %.4f\" fill=\"none\"",
                                   colour, 0.15 * s, 0.1 * s, 0.25 * s));
  }
  AppendEnds(out, plan.path, s, colour, "#000000", colour);
}

// The legend rows: the title and the key, then the robots, as many per row
// as fit the key row's width (at least four).
std::vector<std::pair<std::string, size_t>> LegendRows(const std::vector<FleetSvgRobot>& robots,
                                                       const std::string& title) {
  std::vector<std::pair<std::string, size_t>> rows;  // markup, visible characters
  const std::string key = "dashed: transitions · disc: start · ring: end";
  const std::string lead = title.empty() ? "" : XmlEscaped(title) + " · ";
  rows.push_back({lead + key, title.size() + 3 + key.size()});
  std::vector<std::string> figures;
  size_t widest = 1;
  for (const FleetSvgRobot& r : robots) {
    figures.push_back(absl::StrFormat(" %.0f s", r.duration_s));
    widest = std::max(widest, 3 + r.id.size() + figures.back().size());
  }
  const size_t per_row = std::max(kMinRobotsPerLegendRow, rows[0].second / widest);
  for (size_t i = 0; i < robots.size(); ++i) {
    if (i % per_row == 0) rows.push_back({"", 0});
    absl::StrAppend(&rows.back().first, i % per_row == 0 ? "" : " · ", "<tspan fill=\"",
                    FleetSvgColour(i), "\" font-weight=\"bold\">", XmlEscaped(robots[i].id),
                    "</tspan>", figures[i]);
    rows.back().second += 3 + robots[i].id.size() + figures[i].size();
  }
  return rows;
}

}  // namespace

const char* FleetSvgColour(size_t i) { return kColours[i % kFleetSvgColours]; }

std::string RenderFleetSvg(const std::vector<FleetSvgRobot>& robots, const Grid& grid,
                           const OccupancyMap* map, const SvgZones& zones,
                           const std::string& title) {
  const std::vector<std::pair<std::string, size_t>> rows = LegendRows(robots, title);
  size_t chars = 1;
  for (const auto& row : rows) chars = std::max(chars, row.second);
  // The text fits the map's width; rows are as tall as the text needs, but
  // no taller than the single plan's legend row.
  const SvgFrame one_row = SvgFrameOf(grid, map, 1);
  const double fs = LegendFontSize(one_row, static_cast<double>(chars));
  const SvgFrame f =
      SvgFrameOf(grid, map, static_cast<int>(rows.size()), std::min(one_row.row_h, 1.8 * fs));
  std::string out;
  AppendSvgOpen(&out, f);
  AppendSite(&out, grid, map, zones);
  AppendShares(&out, robots, grid);
  for (size_t i = 0; i < robots.size(); ++i) {
    if (robots[i].plan != nullptr) AppendRobot(&out, *robots[i].plan, FleetSvgColour(i), f.cell);
  }
  std::string legend;
  for (size_t r = 0; r < rows.size(); ++r) {
    absl::StrAppendFormat(&legend,
                          "<text x=\"%.4f\" y=\"%.4f\" font-family=\"sans-serif\" "
                          "font-size=\"%.4f\">%s</text>\n",
                          f.origin.x + 0.2, -f.legend_h + (r + 0.65) * f.row_h, fs, rows[r].first);
  }
  AppendSvgClose(&out, legend);
  return out;
}

}  // namespace covplan
