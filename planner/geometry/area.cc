#include "planner/geometry/area.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <tuple>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/geometry/area_data.h"
#include "planner/geometry/edge_queries.h"
#include "planner/geometry/polygon_union.h"
#include "planner/geometry/polygon_validation.h"

namespace covplan {
namespace {

using geometry_internal::AreaData;
using geometry_internal::BBox;
using geometry_internal::BMultiPolygon;
using geometry_internal::BoxIndex;
using geometry_internal::BPoint;
using geometry_internal::BPolygon;
using geometry_internal::BRing;
using geometry_internal::BSegment;
using geometry_internal::Edge;
using geometry_internal::FromBoost;
using geometry_internal::ToBoost;
namespace bg = geometry_internal::bg;
namespace bgi = geometry_internal::bgi;

bool PointLess(const BPoint& a, const BPoint& b) {
  return std::tie(a.x(), a.y()) < std::tie(b.x(), b.y());
}

// Starts a closed ring at its smallest vertex, so that the text of equal shapes is equal.
void RotateRing(BRing& ring) {
  if (ring.size() < 2) return;
  ring.pop_back();
  std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end(), PointLess), ring.end());
  ring.push_back(ring.front());
}

bool RingLess(const BRing& a, const BRing& b) {
  return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(), PointLess);
}

void Normalise(BMultiPolygon& shape) {
  bg::correct(shape);
  for (BPolygon& p : shape) {
    RotateRing(p.outer());
    for (BRing& hole : p.inners()) RotateRing(hole);
    std::sort(p.inners().begin(), p.inners().end(), RingLess);
  }
  std::sort(shape.begin(), shape.end(),
            [](const BPolygon& a, const BPolygon& b) { return RingLess(a.outer(), b.outer()); });
}

BPolygon RingPolygon(const BRing& ring) {
  BPolygon p;
  p.outer() = ring;
  bg::correct(p);
  return p;
}

void AddEdges(const BRing& ring, AreaData& d) {
  for (size_t i = 0; i + 1 < ring.size(); ++i) {
    d.edges.push_back(Edge{FromBoost(ring[i]), FromBoost(ring[i + 1])});
  }
  d.num_vertices += ring.empty() ? 0 : static_cast<int64_t>(ring.size()) - 1;
}

void AppendRingText(const BRing& ring, std::string& out) {
  out += '(';
  for (size_t i = 0; i < ring.size(); ++i) {
    if (i > 0) out += ',';
    absl::StrAppendFormat(&out, "%.17g %.17g", ring[i].x(), ring[i].y());
  }
  out += ')';
}

std::vector<Point2> RingPoints(const BRing& ring) {
  std::vector<Point2> out;
  out.reserve(ring.size());
  for (const BPoint& p : ring) out.push_back(FromBoost(p));
  return out;
}

bool Finite(Point2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }

double Distance(Point2 p, const Edge& e) {
  return bg::distance(ToBoost(p), BSegment(ToBoost(e.a), ToBoost(e.b)));
}

}  // namespace

absl::StatusOr<Area> Area::Create(const std::vector<PolygonInput>& polygons, std::string_view field,
                                  const AreaLimits& limits) {
  ASSIGN_OR_RETURN(std::vector<BPolygon> valid,
                   geometry_internal::ValidatePolygons(polygons, field, limits));
  auto d = std::make_shared<AreaData>();
  ASSIGN_OR_RETURN(d->shape, geometry_internal::UnionPolygons(std::move(valid), field));
  Normalise(d->shape);
  for (const BPolygon& p : d->shape) {
    AddEdges(p.outer(), *d);
    d->rings.plus.push_back(RingPolygon(p.outer()));
    for (const BRing& hole : p.inners()) {
      AddEdges(hole, *d);
      d->rings.minus.push_back(RingPolygon(hole));
    }
  }
  std::vector<BoxIndex> boxes;
  boxes.reserve(d->edges.size());
  for (size_t i = 0; i < d->edges.size(); ++i) {
    const BSegment s(ToBoost(d->edges[i].a), ToBoost(d->edges[i].b));
    boxes.emplace_back(bg::return_envelope<BBox>(s), static_cast<uint32_t>(i));
  }
  d->edge_tree = geometry_internal::SegmentTree(boxes.begin(), boxes.end());
  if (!d->shape.empty()) {
    const BBox box = bg::return_envelope<BBox>(d->shape);
    d->min_corner = FromBoost(box.min_corner());
    d->max_corner = FromBoost(box.max_corner());
    d->area_m2 = bg::area(d->shape);
  }
  return Area(std::move(d));
}

bool Area::empty() const { return data_ == nullptr || data_->shape.empty(); }
double Area::AreaM2() const { return data_ ? data_->area_m2 : 0.0; }
Point2 Area::min_corner() const { return data_ ? data_->min_corner : Point2{}; }
Point2 Area::max_corner() const { return data_ ? data_->max_corner : Point2{}; }
int64_t Area::num_vertices() const { return data_ ? data_->num_vertices : 0; }

bool Area::Contains(Point2 p) const {
  if (empty() || !Finite(p)) return false;
  return bg::covered_by(ToBoost(p), data_->shape);
}

bool Area::InInterior(Point2 p) const {
  if (empty() || !Finite(p)) return false;
  return bg::within(ToBoost(p), data_->shape);
}

double Area::SegmentLengthInInterior(Point2 a, Point2 b) const {
  if (empty() || !Finite(a) || !Finite(b)) return 0.0;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  if (!(len2 > 0) || !std::isfinite(len2)) return 0.0;
  const BSegment seg(ToBoost(a), ToBoost(b));
  // Split a-b where it meets the boundary; each piece is then wholly inside or outside, or
  // runs along the boundary.
  std::vector<double> ts = {0.0, 1.0};
  std::vector<BoxIndex> hits;
  data_->edge_tree.query(bgi::intersects(bg::return_envelope<BBox>(seg)), std::back_inserter(hits));
  std::vector<BPoint> points;
  for (const BoxIndex& hit : hits) {
    const Edge& e = data_->edges[hit.second];
    points.clear();
    bg::intersection(seg, BSegment(ToBoost(e.a), ToBoost(e.b)), points);
    for (const BPoint& p : points) {
      ts.push_back(std::clamp(((p.x() - a.x) * dx + (p.y() - a.y) * dy) / len2, 0.0, 1.0));
    }
  }
  std::sort(ts.begin(), ts.end());
  const double len = std::sqrt(len2);
  const double tol =
      1e-9 + 1e-13 * std::max({std::abs(a.x), std::abs(a.y), std::abs(b.x), std::abs(b.y)});
  auto at = [&](double t) { return Point2{a.x + t * dx, a.y + t * dy}; };
  double inside = 0.0;
  for (size_t i = 0; i + 1 < ts.size(); ++i) {
    if ((ts[i + 1] - ts[i]) * len <= 1e-12) continue;
    const Point2 p = at(ts[i]), q = at(ts[i + 1]), mid = at(0.5 * (ts[i] + ts[i + 1]));
    bool along_boundary = false;
    hits.clear();
    data_->edge_tree.query(
        bgi::intersects(BBox(BPoint(mid.x - tol, mid.y - tol), BPoint(mid.x + tol, mid.y + tol))),
        std::back_inserter(hits));
    for (const BoxIndex& hit : hits) {
      const Edge& e = data_->edges[hit.second];
      if (Distance(mid, e) <= tol && Distance(p, e) <= tol && Distance(q, e) <= tol) {
        along_boundary = true;
        break;
      }
    }
    if (!along_boundary && bg::within(ToBoost(mid), data_->shape)) {
      inside += (ts[i + 1] - ts[i]) * len;
    }
  }
  return inside;
}

double Area::BoxOverlapM2(double x0, double y0, double x1, double y1) const {
  if (empty() || !std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) ||
      !std::isfinite(y1) || !(x0 < x1) || !(y0 < y1)) {
    return 0.0;
  }
  const Point2 lo = data_->min_corner, hi = data_->max_corner;
  if (x1 <= lo.x || x0 >= hi.x || y1 <= lo.y || y0 >= hi.y) return 0.0;
  if (x0 <= lo.x && y0 <= lo.y && x1 >= hi.x && y1 >= hi.y) return data_->area_m2;
  const geometry_internal::AreaData& d = *data_;
  // Clip to a box half as large again first, so that the final clip's snapping grid (1e-7 of
  // its inputs' extent) is that of the box, not of the whole area.
  const double mx = std::max(0.5 * (x1 - x0), 1e-5 * (hi.x - lo.x));
  const double my = std::max(0.5 * (y1 - y0), 1e-5 * (hi.y - lo.y));
  const geometry_internal::RingPieces near =
      geometry_internal::ClipToBox(d.rings, x0 - mx, y0 - my, x1 + mx, y1 + my);
  return geometry_internal::ClipBoxM2(d, near, x0, y0, x1, y1,
                                      [&d](Point2 p) { return bg::within(ToBoost(p), d.shape); });
}

std::string Area::CanonicalText() const {
  if (empty()) return "MULTIPOLYGON EMPTY";
  std::string out = "MULTIPOLYGON(";
  for (size_t i = 0; i < data_->shape.size(); ++i) {
    const BPolygon& p = data_->shape[i];
    if (i > 0) out += ',';
    out += '(';
    AppendRingText(p.outer(), out);
    for (const BRing& hole : p.inners()) {
      out += ',';
      AppendRingText(hole, out);
    }
    out += ')';
  }
  out += ')';
  return out;
}

std::vector<PolygonInput> Area::ToPolygons() const {
  std::vector<PolygonInput> out;
  if (empty()) return out;
  for (const BPolygon& p : data_->shape) {
    PolygonInput in;
    in.outer = RingPoints(p.outer());
    for (const BRing& hole : p.inners()) in.holes.push_back(RingPoints(hole));
    out.push_back(std::move(in));
  }
  return out;
}

}  // namespace covplan
