#include "planner/plan/svg_layers.h"

#include <algorithm>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace covplan::svg_internal {

SvgFrame SvgFrameOf(const Grid& grid, const OccupancyMap* map, int legend_rows, double row_h) {
  SvgFrame f;
  f.cell = grid.cell_size();
  f.origin = grid.origin();
  f.width = grid.cols() * f.cell;
  f.height = grid.rows() * f.cell;
  if (map) {
    f.width = std::max(f.width, map->width() * map->resolution());
    f.height = std::max(f.height, map->height() * map->resolution());
  }
  f.row_h = row_h > 0.0 ? row_h : 0.06 * std::max(f.width, f.height) + 1.0;
  f.legend_h = std::max(1, legend_rows) * f.row_h;
  return f;
}

void AppendSvgOpen(std::string* out, const SvgFrame& f) {
  const double w = f.width, h = f.height;
  const Point2 o = f.origin;
  const double px_per_m = std::clamp(1600.0 / std::max(w, h), 2.0, 60.0);
  absl::StrAppendFormat(out,
                        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                        "viewBox=\"%.4f %.4f %.4f %.4f\">\n",
                        w * px_per_m, (h + f.legend_h) * px_per_m, o.x, -f.legend_h, w,
                        h + f.legend_h);
  absl::StrAppendFormat(
      out, "<rect x=\"%.4f\" y=\"%.4f\" width=\"%.4f\" height=\"%.4f\" fill=\"#ffffff\"/>\n", o.x,
      -f.legend_h, w, h + f.legend_h);
  // Map frame: y up. Flip about the map's vertical extent.
  absl::StrAppendFormat(out, "<g transform=\"matrix(1 0 0 -1 0 %.4f)\">\n", h + 2 * o.y);
}

void AppendSvgClose(std::string* out, const std::string& legend) {
  absl::StrAppend(out, "</g>\n", legend, "</svg>\n");
}

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

void AppendSite(std::string* out, const Grid& grid, const OccupancyMap* map,
                const SvgZones& zones) {
  const double s = grid.cell_size();
  const Point2 o = grid.origin();
  AppendRuns(out, grid.rows(), grid.cols(), o.x, o.y, s, "#e3ecf7",
             [&](int r, int c) { return grid.IsFree(r, c); });
  if (map) {
    const Point2 mo = map->origin();
    const double res = map->resolution();
    AppendRuns(out, map->height(), map->width(), mo.x, mo.y, res, "#b8b8b8",
               [&](int r, int c) { return map->at(r, c) == CellState::kUnknown; });
    AppendRuns(out, map->height(), map->width(), mo.x, mo.y, res, "#202020",
               [&](int r, int c) { return map->at(r, c) == CellState::kOccupied; });
  }
  AppendPolygons(out, zones.regions, "#4a90d9", "#1f5fa8", 0.08 * s);
  AppendPolygons(out, zones.no_go, "#e03131", "#a61e1e", 0.08 * s);
}

void AppendSegments(std::string* out, const std::vector<Waypoint>& path,
                    const std::vector<SegmentKind>& kinds, const std::string& group_attributes) {
  absl::StrAppend(out, "<g ", group_attributes, ">\n");
  for (size_t i = 1; i < path.size(); ++i) {
    if (std::find(kinds.begin(), kinds.end(), path[i].kind) == kinds.end()) continue;
    absl::StrAppendFormat(out, "<line x1=\"%.4f\" y1=\"%.4f\" x2=\"%.4f\" y2=\"%.4f\"/>\n",
                          path[i - 1].x, path[i - 1].y, path[i].x, path[i].y);
  }
  absl::StrAppend(out, "</g>\n");
}

void AppendEnds(std::string* out, const std::vector<Waypoint>& path, double s,
                const char* start_fill, const char* start_stroke, const char* end_stroke) {
  if (path.empty()) return;
  const Waypoint& st = path.front();
  const Waypoint& en = path.back();
  const std::string outline =
      start_stroke[0] == '\0'
          ? std::string()
          : absl::StrFormat(" stroke=\"%s\" stroke-width=\"%.4f\"", start_stroke, 0.12 * s);
  absl::StrAppendFormat(out, "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"%.4f\" fill=\"%s\"%s/>\n", st.x,
                        st.y, 0.45 * s, start_fill, outline);
  absl::StrAppendFormat(out,
                        "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"%.4f\" fill=\"none\" "
                        "stroke=\"%s\" stroke-width=\"%.4f\"/>\n",
                        en.x, en.y, 0.6 * s, end_stroke, 0.15 * s);
}

double LegendFontSize(const SvgFrame& f, double chars) {
  return std::max(std::min(0.45 * f.row_h, (f.width - 0.4) / (0.56 * chars)), 1e-3);
}

}  // namespace covplan::svg_internal
