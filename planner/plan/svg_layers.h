// The layers RenderPlanSvg (svg.h) and RenderFleetSvg (fleet_svg.h) draw a
// plan with: the frame (the SVG element, y flipped to the map frame, room for
// a legend above the map), the site (free cells, the map's unknown and
// occupied pixels, regions and no-go zones), runs of cells, segment lines and
// the start and end markers. Internal to planner/plan.
//
//   SvgFrame f = SvgFrameOf(grid, map, /*legend_rows=*/1);
//   std::string out;
//   AppendSvgOpen(&out, f);
//   AppendSite(&out, grid, map, zones);
//   ... layers in map coordinates ...
//   AppendSvgClose(&out, legend_text);
//
// Thread-safety: stateless.
#ifndef COVPLAN_PLANNER_PLAN_SVG_LAYERS_H_
#define COVPLAN_PLANNER_PLAN_SVG_LAYERS_H_

#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"
#include "planner/plan/coverage_plan.h"
#include "planner/plan/svg.h"

namespace covplan::svg_internal {

// Where the drawing lies, in metres: the map's frame below a legend band of
// `legend_rows` rows of height `row_h` (the band spans y in [-legend_h, 0)).
// The default row height is 6 % of the map's larger side plus 1 m; a
// positive `row_h` overrides it (rows of small text).
struct SvgFrame {
  Point2 origin;
  double width = 0.0, height = 0.0;  // the map (or grid) extent
  double cell = 0.0;                 // the grid's cell size
  double row_h = 0.0, legend_h = 0.0;
};
SvgFrame SvgFrameOf(const Grid& grid, const OccupancyMap* map, int legend_rows, double row_h = 0.0);

// The XML header, the <svg> element, a white background and the opening of
// the group in map coordinates (y up); AppendSvgClose closes that group,
// appends `legend` (text elements in legend coordinates) and closes the SVG.
void AppendSvgOpen(std::string* out, const SvgFrame& f);
void AppendSvgClose(std::string* out, const std::string& legend);

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

void AppendPolygons(std::string* out, const std::vector<PolygonInput>& polygons, const char* fill,
                    const char* stroke, double stroke_width);

// The site under the paths: the grid's free cells, the map's unknown and
// occupied pixels (when `map` is given), regions (blue) and no-go zones (red).
void AppendSite(std::string* out, const Grid& grid, const OccupancyMap* map, const SvgZones& zones);

// One <line> per segment of `path` whose end waypoint's kind is one of
// `kinds`, in a group with `group_attributes` (stroke, width, dashes).
void AppendSegments(std::string* out, const std::vector<Waypoint>& path,
                    const std::vector<SegmentKind>& kinds, const std::string& group_attributes);

// The path's start (a disc filled `start_fill`, outlined `start_stroke` when
// not empty) and end (a ring of `end_stroke`), sized from the cell size `s`.
void AppendEnds(std::string* out, const std::vector<Waypoint>& path, double s,
                const char* start_fill, const char* start_stroke, const char* end_stroke);

// The font size that fits `chars` characters of sans-serif text (about
// 0.56 em each) into width `w`, at most 0.45 of the row height.
double LegendFontSize(const SvgFrame& f, double chars);

}  // namespace covplan::svg_internal

#endif  // COVPLAN_PLANNER_PLAN_SVG_LAYERS_H_
