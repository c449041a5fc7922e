// Internal to planner/geometry: queries on an Area's boundary edges (through its R-tree), and
// box clipping that survives Boost.Geometry 1.74's overlay on near-degenerate boxes.
//
// Boost 1.74 snaps overlay points to ~1e-7 of the inputs' extent. Ways that goes wrong, all
// found by fuzz/geojson_fuzzer: a box whose corner lies on a ring's edge can come back as the
// whole box or nothing; polygons of one multipolygon that touch at a point (or a hole touching
// its outer ring) can look as if they cross, spoiling the whole overlay. So: boxes are clipped
// against one ring at a time (RingPieces: outer rings add, holes subtract); an all-or-nothing
// clip of a ring is checked with point tests and redone on the box's quarters if it fails;
// ClipBoxM2 only clips boxes the boundary really enters, and overrules an all-or-nothing total
// that contradicts the box centre when the centre is well away from every edge.
//
//   double a = ClipBoxM2(d, d.rings, x0, y0, x1, y1, [&](Point2 p) { return Within(d, p); });
//
// Thread-safety: stateless functions over immutable data.
#ifndef COVPLAN_PLANNER_GEOMETRY_EDGE_QUERIES_H_
#define COVPLAN_PLANNER_GEOMETRY_EDGE_QUERIES_H_

#include <algorithm>

#include "planner/geometry/area_data.h"

namespace covplan::geometry_internal {

// Whether an edge comes within `radius` of p.
bool EdgeNear(const AreaData& d, Point2 p, double radius);

// Whether an edge enters the open box (x0, x1) x (y0, y1), shrunk by 1e-9 of its smaller
// side. If none does, the whole box is inside or outside, as its centre is.
bool EdgeEntersBox(const AreaData& d, double x0, double y0, double x1, double y1);

// The rings' parts inside the box.
RingPieces ClipToBox(const RingPieces& rings, double x0, double y0, double x1, double y1);

// Area of the rings within the box: outer parts minus hole parts.
double BoxAreaM2(const RingPieces& rings, double x0, double y0, double x1, double y1);

// Area of d.shape within the box, where `rings` is d.rings or a piece of it covering the box.
// `inside(p)` tells whether p lies in the area; it is only asked about points at least 1% of
// the box's smaller side away from every edge (so a parity test is exact there).
template <typename InsideFn>
double ClipBoxM2(const AreaData& d, const RingPieces& rings, double x0, double y0, double x1,
                 double y1, const InsideFn& inside) {
  const double box_area = (x1 - x0) * (y1 - y0);
  const Point2 centre{0.5 * (x0 + x1), 0.5 * (y0 + y1)};
  if (!EdgeEntersBox(d, x0, y0, x1, y1)) return inside(centre) ? box_area : 0.0;
  double a = std::clamp(BoxAreaM2(rings, x0, y0, x1, y1), 0.0, box_area);
  if (!(a >= 0)) a = 0;  // NaN from overflowing coordinates
  const double tiny = 1e-6 * box_area;
  if ((a < tiny || a > box_area - tiny) &&
      !EdgeNear(d, centre, 0.01 * std::min(x1 - x0, y1 - y0))) {
    // A disc of 1% of the side around the centre is on the centre's side: all-or-nothing
    // answers that disagree with it are overlay failures, and the edge barely enters.
    const bool in = inside(centre);
    if (in && a < tiny) a = box_area;
    if (!in && a > box_area - tiny) a = 0;
  }
  return a;
}

}  // namespace covplan::geometry_internal

#endif  // COVPLAN_PLANNER_GEOMETRY_EDGE_QUERIES_H_
