#include "planner/geometry/polygon_validation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"

namespace covplan::geometry_internal {
namespace {

std::string FormatNumber(double v) {
  std::string s = absl::StrFormat("%g", v);
  if (std::strtod(s.c_str(), nullptr) != v) s = absl::StrFormat("%.17g", v);
  return s;
}

bool SamePoint(Point2 a, Point2 b) { return a.x == b.x && a.y == b.y; }

absl::Status RingError(const std::string& name, std::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat(name, ": ", std::string(what)));
}

// All points within 1e-12 (relative to the ring's size) of one line.
bool Collinear(const std::vector<Point2>& ring) {
  const Point2 p0 = ring[0];
  Point2 far = p0;
  double far_d2 = 0.0;
  for (const Point2& p : ring) {
    const double d2 = (p.x - p0.x) * (p.x - p0.x) + (p.y - p0.y) * (p.y - p0.y);
    if (d2 > far_d2) far_d2 = d2, far = p;
  }
  const double dx = far.x - p0.x, dy = far.y - p0.y;
  for (const Point2& p : ring) {
    const double cross = dx * (p.y - p0.y) - dy * (p.x - p0.x);
    if (std::abs(cross) > 1e-12 * far_d2) return false;
  }
  return true;
}

// The first pair of edges (by input index) that intersect other than at a shared vertex of
// consecutive edges. Edge i runs from input vertex i to vertex i + 1; zero-length edges
// (repeated points) are skipped.
std::optional<std::string> FindSelfIntersection(const std::vector<Point2>& ring) {
  std::vector<int> edges;  // input index of each non-degenerate edge
  for (size_t i = 0; i + 1 < ring.size(); ++i) {
    if (!SamePoint(ring[i], ring[i + 1])) edges.push_back(static_cast<int>(i));
  }
  const int m = static_cast<int>(edges.size());
  auto segment = [&](int k) {
    return BSegment(ToBoost(ring[edges[k]]), ToBoost(ring[edges[k] + 1]));
  };
  std::vector<BoxIndex> boxes;
  boxes.reserve(m);
  for (int k = 0; k < m; ++k) boxes.emplace_back(bg::return_envelope<BBox>(segment(k)), k);
  const SegmentTree tree(boxes.begin(), boxes.end());
  std::vector<BoxIndex> hits;
  for (int j = 0; j < m; ++j) {
    hits.clear();
    tree.query(bgi::intersects(boxes[j].first), std::back_inserter(hits));
    std::sort(hits.begin(), hits.end(),
              [](const BoxIndex& a, const BoxIndex& b) { return a.second < b.second; });
    const BSegment sj = segment(j);
    for (const BoxIndex& hit : hits) {
      const int k = static_cast<int>(hit.second);
      if (k <= j) continue;
      std::vector<BPoint> points;
      bg::intersection(sj, segment(k), points);
      const bool adjacent = k == j + 1 || (j == 0 && k == m - 1);
      // Consecutive edges share a vertex; they are wrong only when they overlap (a spike).
      if (points.empty() || (adjacent && points.size() < 2)) continue;
      Point2 at = FromBoost(points[0]);
      if (adjacent && points.size() >= 2) {
        const Point2 shared = k == j + 1 ? ring[edges[k]] : ring[edges[j]];
        if (SamePoint(at, shared)) at = FromBoost(points[1]);
      }
      return absl::StrFormat("ring intersects itself at %s (edges %d and %d)", FormatPoint(at),
                             edges[j], edges[k]);
    }
  }
  return std::nullopt;
}

absl::Status CheckRing(const std::vector<Point2>& ring, const std::string& name) {
  for (size_t i = 0; i < ring.size(); ++i) {
    if (!std::isfinite(ring[i].x) || !std::isfinite(ring[i].y)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s vertex %d: coordinate is not a finite number", name, i));
    }
  }
  if (!ring.empty() && !SamePoint(ring.front(), ring.back())) {
    return RingError(name, absl::StrFormat("ring is not closed: first point %s differs from last "
                                           "point %s",
                                           FormatPoint(ring.front()), FormatPoint(ring.back())));
  }
  std::vector<std::pair<double, double>> distinct;
  distinct.reserve(ring.size());
  for (size_t i = 0; i + 1 < ring.size(); ++i) distinct.emplace_back(ring[i].x, ring[i].y);
  std::sort(distinct.begin(), distinct.end());
  const size_t num_distinct = std::unique(distinct.begin(), distinct.end()) - distinct.begin();
  if (num_distinct < 3) {
    return RingError(
        name, absl::StrFormat("ring has %d distinct points; at least 3 are needed", num_distinct));
  }
  if (Collinear(ring)) return RingError(name, "ring has zero area (all points on one line)");
  if (std::optional<std::string> crossing = FindSelfIntersection(ring)) {
    return RingError(name, *crossing);
  }
  return absl::OkStatus();
}

BRing ToRing(const std::vector<Point2>& points) {
  BRing ring;
  ring.reserve(points.size());
  for (const Point2& p : points) {
    // Repeated consecutive points carry no shape and only upset the overlay.
    if (!ring.empty() && SamePoint(FromBoost(ring.back()), p)) continue;
    ring.push_back(ToBoost(p));
  }
  return ring;
}

BPolygon RingPolygon(const BRing& ring) {
  BPolygon p;
  p.outer() = ring;
  bg::correct(p);
  return p;
}

// Holes inside the outer ring and apart from each other, and whatever else Boost's validity
// test finds (e.g. holes that cut the interior in two).
absl::Status CheckHoles(const BPolygon& polygon, const std::string& name) {
  const BPolygon outer = RingPolygon(polygon.outer());
  std::vector<BPolygon> holes;
  std::vector<BoxIndex> boxes;
  for (size_t h = 0; h < polygon.inners().size(); ++h) {
    holes.push_back(RingPolygon(polygon.inners()[h]));
    boxes.emplace_back(bg::return_envelope<BBox>(holes.back()), static_cast<uint32_t>(h));
    if (!bg::covered_by(holes.back(), outer)) {
      const bool interiors_meet = bg::relate(holes.back(), outer, bg::de9im::mask("T********"));
      return absl::InvalidArgumentError(
          absl::StrFormat("%s.holes[%d]: hole lies %soutside its outer ring", name, h,
                          interiors_meet ? "partly " : ""));
    }
  }
  const SegmentTree tree(boxes.begin(), boxes.end());
  std::vector<BoxIndex> hits;
  for (size_t h = 0; h < holes.size(); ++h) {
    hits.clear();
    tree.query(bgi::intersects(boxes[h].first), std::back_inserter(hits));
    uint32_t first = UINT32_MAX;
    for (const BoxIndex& hit : hits) {
      if (hit.second < h && hit.second < first &&
          bg::relate(holes[h], holes[hit.second], bg::de9im::mask("T********"))) {
        first = hit.second;
      }
    }
    if (first != UINT32_MAX) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s.holes[%d]: hole overlaps holes[%d]", name, h, first));
    }
  }
  std::string reason;
  if (!bg::is_valid(polygon, reason)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": invalid polygon: ", reason));
  }
  return absl::OkStatus();
}

}  // namespace

std::string FormatPoint(Point2 p) {
  return absl::StrCat("(", FormatNumber(p.x), ", ", FormatNumber(p.y), ")");
}

absl::StatusOr<std::vector<BPolygon>> ValidatePolygons(const std::vector<PolygonInput>& polygons,
                                                       std::string_view field,
                                                       const AreaLimits& limits) {
  int64_t total = 0;
  for (const PolygonInput& p : polygons) {
    total += static_cast<int64_t>(p.outer.size());
    for (const auto& hole : p.holes) total += static_cast<int64_t>(hole.size());
  }
  if (total > limits.max_vertices) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: %d vertices exceed the limit of %d",
                                                      field, total, limits.max_vertices));
  }
  double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
  auto extend = [&](const std::vector<Point2>& ring) {
    for (const Point2& p : ring) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;  // reported with its ring
      lo_x = std::min(lo_x, p.x), hi_x = std::max(hi_x, p.x);
      lo_y = std::min(lo_y, p.y), hi_y = std::max(hi_y, p.y);
    }
  };
  for (const PolygonInput& p : polygons) {
    extend(p.outer);
    for (const auto& hole : p.holes) extend(hole);
  }
  const double extent = std::max(hi_x - lo_x, hi_y - lo_y);
  if (extent > limits.max_extent_m) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s: the polygons span %g m, more than the limit of %g m", field, extent,
                        limits.max_extent_m));
  }
  std::vector<BPolygon> out;
  out.reserve(polygons.size());
  for (size_t i = 0; i < polygons.size(); ++i) {
    const PolygonInput& in = polygons[i];
    const std::string name = absl::StrFormat("%s[%d]", field, i);
    RETURN_IF_ERROR(CheckRing(in.outer, name + ".outer"));
    BPolygon polygon;
    polygon.outer() = ToRing(in.outer);
    for (size_t h = 0; h < in.holes.size(); ++h) {
      RETURN_IF_ERROR(CheckRing(in.holes[h], absl::StrFormat("%s.holes[%d]", name, h)));
      polygon.inners().push_back(ToRing(in.holes[h]));
    }
    bg::correct(polygon);
    RETURN_IF_ERROR(CheckHoles(polygon, name));
    out.push_back(std::move(polygon));
  }
  return out;
}

}  // namespace covplan::geometry_internal
