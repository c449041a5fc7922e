// Internal to planner/geometry: the Boost.Geometry types behind an Area and the data an Area
// shares between its copies. Include only from planner/geometry/*.cc: Boost.Geometry costs
// seconds of compile time per translation unit.
//
//   const AreaData& d = ...;
//   bg::covered_by(ToBoost(p), d.shape);
//
// Thread-safety: AreaData is built once in Area::Create and never modified afterwards.
#ifndef COVPLAN_PLANNER_GEOMETRY_AREA_DATA_H_
#define COVPLAN_PLANNER_GEOMETRY_AREA_DATA_H_

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/box.hpp>
#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#include <boost/geometry/geometries/segment.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cstdint>
#include <utility>
#include <vector>

#include "planner/grid/occupancy_map.h"

namespace covplan::geometry_internal {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

using BPoint = bg::model::d2::point_xy<double>;
// Counter-clockwise outer rings (as RFC 7946 asks), closed.
using BPolygon = bg::model::polygon<BPoint, /*ClockWise=*/false, /*Closed=*/true>;
using BRing = BPolygon::ring_type;
using BMultiPolygon = bg::model::multi_polygon<BPolygon>;
using BBox = bg::model::box<BPoint>;
using BSegment = bg::model::segment<BPoint>;
using BoxIndex = std::pair<BBox, uint32_t>;
using SegmentTree = bgi::rtree<BoxIndex, bgi::quadratic<16>>;

inline BPoint ToBoost(Point2 p) { return BPoint(p.x, p.y); }
inline Point2 FromBoost(const BPoint& p) { return Point2{p.x(), p.y()}; }

// A closed counter-clockwise polygon for the box [x0, x1] x [y0, y1].
inline BPolygon BoxPolygon(double x0, double y0, double x1, double y1) {
  BPolygon p;
  p.outer() = {BPoint(x0, y0), BPoint(x1, y0), BPoint(x1, y1), BPoint(x0, y1), BPoint(x0, y0)};
  return p;
}

struct Edge {
  Point2 a;
  Point2 b;
};

// An area as its outer rings minus its holes, each ring a polygon of its own (counter-
// clockwise, no holes). Boost 1.74's overlay is most reliable for a box against one simple
// ring; rings that touch each other at a point are a case it gets wrong.
struct RingPieces {
  BMultiPolygon plus;
  BMultiPolygon minus;
};

struct AreaData {
  BMultiPolygon shape;      // valid, normalised (see Area::CanonicalText)
  RingPieces rings;         // the rings of `shape`
  std::vector<Edge> edges;  // every boundary edge of every ring
  SegmentTree edge_tree;    // envelopes of `edges`, value = index into edges
  Point2 min_corner;
  Point2 max_corner;
  double area_m2 = 0.0;
  int64_t num_vertices = 0;
};

}  // namespace covplan::geometry_internal

#endif  // COVPLAN_PLANNER_GEOMETRY_AREA_DATA_H_
