#include "planner/geometry/edge_queries.h"

#include <iterator>
#include <vector>

namespace covplan::geometry_internal {

bool EdgeNear(const AreaData& d, Point2 p, double radius) {
  std::vector<BoxIndex> hits;
  d.edge_tree.query(
      bgi::intersects(BBox(BPoint(p.x - radius, p.y - radius), BPoint(p.x + radius, p.y + radius))),
      std::back_inserter(hits));
  for (const BoxIndex& hit : hits) {
    const Edge& e = d.edges[hit.second];
    if (bg::comparable_distance(ToBoost(p), BSegment(ToBoost(e.a), ToBoost(e.b))) <=
        radius * radius) {
      return true;
    }
  }
  return false;
}

bool EdgeEntersBox(const AreaData& d, double x0, double y0, double x1, double y1) {
  const double shrink = 1e-9 * std::min(x1 - x0, y1 - y0);
  const BBox inner(BPoint(x0 + shrink, y0 + shrink), BPoint(x1 - shrink, y1 - shrink));
  std::vector<BoxIndex> hits;
  d.edge_tree.query(bgi::intersects(inner), std::back_inserter(hits));
  for (const BoxIndex& hit : hits) {
    const Edge& e = d.edges[hit.second];
    if (bg::intersects(BSegment(ToBoost(e.a), ToBoost(e.b)), inner)) return true;
  }
  return false;
}

namespace {

// Whether an all-or-nothing clip of `box` by ring polygon p is believable: the centres of the
// box's quarters (off its corners and centre lines, where the degenerate cases sit) must all
// be inside p for "whole box" and none strictly inside for "nothing".
bool AllOrNothingHolds(const BPolygon& p, const BBox& box, bool whole) {
  const double x0 = box.min_corner().x(), y0 = box.min_corner().y();
  const double w = box.max_corner().x() - x0, h = box.max_corner().y() - y0;
  for (double fx : {0.25, 0.75}) {
    for (double fy : {0.25, 0.75}) {
      const BPoint q(x0 + fx * w, y0 + fy * h);
      if (whole ? !bg::covered_by(q, p) : bg::within(q, p)) return false;
    }
  }
  return true;
}

// Area of box and ring polygon p. Boost 1.74 sometimes returns the whole box or nothing when
// p's boundary passes through a box corner; an answer that fails AllOrNothingHolds is redone
// on the four quarters (new corners), down to boxes 1/16 the side, where the quarter-centre
// tests decide.
double RingBoxArea(const BPolygon& p, const BBox& box, int depth) {
  BMultiPolygon part;
  bg::intersection(BoxPolygon(box.min_corner().x(), box.min_corner().y(), box.max_corner().x(),
                              box.max_corner().y()),
                   p, part);
  const double box_area = bg::area(box);
  const double a = bg::area(part);
  const bool whole = a >= box_area * (1 - 1e-9), nothing = a <= box_area * 1e-9;
  if ((!whole && !nothing) || AllOrNothingHolds(p, box, whole)) return a;
  const double x0 = box.min_corner().x(), y0 = box.min_corner().y();
  const double xm = 0.5 * (x0 + box.max_corner().x()), ym = 0.5 * (y0 + box.max_corner().y());
  const BBox quarters[4] = {BBox(box.min_corner(), BPoint(xm, ym)),
                            BBox(BPoint(xm, y0), BPoint(box.max_corner().x(), ym)),
                            BBox(BPoint(x0, ym), BPoint(xm, box.max_corner().y())),
                            BBox(BPoint(xm, ym), box.max_corner())};
  double sum = 0.0;
  for (const BBox& q : quarters) {
    if (depth < 4) {
      sum += RingBoxArea(p, q, depth + 1);
    } else {
      sum += bg::covered_by(bg::return_centroid<BPoint>(q), p) ? bg::area(q) : 0.0;
    }
  }
  return sum;
}

// Clipped pieces only speed up later clips, so a piece that fails AllOrNothingHolds is kept
// whole instead.
void ClipEach(const BMultiPolygon& polygons, const BBox& box, BMultiPolygon& out) {
  const BPolygon box_polygon = BoxPolygon(box.min_corner().x(), box.min_corner().y(),
                                          box.max_corner().x(), box.max_corner().y());
  const double box_area = bg::area(box);
  BMultiPolygon part;
  for (const BPolygon& p : polygons) {
    if (bg::disjoint(bg::return_envelope<BBox>(p), box)) continue;
    part.clear();
    bg::intersection(box_polygon, p, part);
    const double a = bg::area(part);
    const bool whole = a >= box_area * (1 - 1e-9), nothing = a <= box_area * 1e-9;
    if ((whole || nothing) && !AllOrNothingHolds(p, box, whole)) {
      out.push_back(p);
      continue;
    }
    for (BPolygon& q : part) out.push_back(std::move(q));
  }
}

}  // namespace

RingPieces ClipToBox(const RingPieces& rings, double x0, double y0, double x1, double y1) {
  const BBox box(BPoint(x0, y0), BPoint(x1, y1));
  RingPieces out;
  ClipEach(rings.plus, box, out.plus);
  ClipEach(rings.minus, box, out.minus);
  return out;
}

double BoxAreaM2(const RingPieces& rings, double x0, double y0, double x1, double y1) {
  const BBox box(BPoint(x0, y0), BPoint(x1, y1));
  double sum = 0.0;
  for (const BPolygon& p : rings.plus) {
    if (!bg::disjoint(bg::return_envelope<BBox>(p), box)) sum += RingBoxArea(p, box, 0);
  }
  for (const BPolygon& p : rings.minus) {
    if (!bg::disjoint(bg::return_envelope<BBox>(p), box)) sum -= RingBoxArea(p, box, 0);
  }
  return sum;
}

}  // namespace covplan::geometry_internal
