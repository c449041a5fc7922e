#include "planner/geometry/polygon_union.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <iterator>
#include <numeric>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace covplan::geometry_internal {
namespace {

// Groups of polygons whose envelopes overlap or touch, transitively (union-find).
std::vector<std::vector<size_t>> EnvelopeGroups(const std::vector<BPolygon>& polygons) {
  std::vector<BoxIndex> boxes;
  boxes.reserve(polygons.size());
  for (size_t i = 0; i < polygons.size(); ++i) {
    boxes.emplace_back(bg::return_envelope<BBox>(polygons[i]), static_cast<uint32_t>(i));
  }
  const SegmentTree tree(boxes.begin(), boxes.end());
  std::vector<size_t> parent(polygons.size());
  std::iota(parent.begin(), parent.end(), size_t{0});
  auto find = [&parent](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::vector<BoxIndex> hits;
  for (const BoxIndex& b : boxes) {
    hits.clear();
    tree.query(bgi::intersects(b.first), std::back_inserter(hits));
    for (const BoxIndex& h : hits) parent[find(h.second)] = find(b.second);
  }
  std::vector<std::vector<size_t>> groups(polygons.size());
  for (size_t i = 0; i < polygons.size(); ++i) groups[find(i)].push_back(i);
  groups.erase(
      std::remove_if(groups.begin(), groups.end(), [](const auto& g) { return g.empty(); }),
      groups.end());
  return groups;
}

BMultiPolygon UnionTree(std::vector<BMultiPolygon> parts) {
  while (parts.size() > 1) {
    std::vector<BMultiPolygon> next;
    next.reserve((parts.size() + 1) / 2);
    for (size_t i = 0; i + 1 < parts.size(); i += 2) {
      BMultiPolygon u;
      bg::union_(parts[i], parts[i + 1], u);
      next.push_back(std::move(u));
    }
    if (parts.size() % 2 == 1) next.push_back(std::move(parts.back()));
    parts = std::move(next);
  }
  return parts.empty() ? BMultiPolygon() : std::move(parts[0]);
}

// The finest feature of a ring: its shortest edge, or its width 2 * area / longest edge (a
// sliver can have long edges only).
double FinestFeature(const BRing& ring) {
  double shortest = INFINITY, longest = 0.0;
  for (size_t k = 0; k + 1 < ring.size(); ++k) {
    const double len = bg::distance(ring[k], ring[k + 1]);
    shortest = std::min(shortest, len);
    longest = std::max(longest, len);
  }
  return std::min(shortest, 2 * std::abs(bg::area(ring)) / longest);
}

// A failed union is the input's fault when it has features below 1e-4 of the group's extent,
// i.e. within 1000 steps of Boost's snapping grid; otherwise it is ours.
absl::Status UnionFailed(const std::vector<BPolygon>& polygons, const std::vector<size_t>& group,
                         std::string_view field, const std::string& reason) {
  BBox box = bg::make_inverse<BBox>();
  double finest = INFINITY;
  for (size_t i : group) {
    bg::expand(box, bg::return_envelope<BBox>(polygons[i]));
    finest = std::min(finest, FinestFeature(polygons[i].outer()));
    for (const BRing& hole : polygons[i].inners()) finest = std::min(finest, FinestFeature(hole));
  }
  const double extent = std::max(box.max_corner().x() - box.min_corner().x(),
                                 box.max_corner().y() - box.min_corner().y());
  const std::string which = group.size() == 1
                                ? absl::StrFormat("%s[%d]", field, group[0])
                                : absl::StrFormat("%s[%d] and %d other polygon(s) overlapping it",
                                                  field, group[0], group.size() - 1);
  if (!(finest >= 1e-4 * extent)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: too fine for their extent (finest part %g m, an edge or a sliver's width, in %g m; "
        "Boost.Geometry snaps to 1e-7 of the extent), the union came out invalid: %s",
        which, finest, extent, reason));
  }
  return absl::InternalError(
      absl::StrFormat("%s: the union of the polygons came out invalid: %s", which, reason));
}

}  // namespace

absl::StatusOr<BMultiPolygon> UnionPolygons(std::vector<BPolygon> polygons,
                                            std::string_view field) {
  BMultiPolygon out;
  for (const std::vector<size_t>& group : EnvelopeGroups(polygons)) {
    if (group.size() == 1) {
      out.push_back(polygons[group[0]]);  // validated on its own
      continue;
    }
    std::vector<BMultiPolygon> parts;
    parts.reserve(group.size());
    for (size_t i : group) parts.push_back(BMultiPolygon{polygons[i]});
    BMultiPolygon u;
    std::string reason;
    try {
      u = UnionTree(std::move(parts));
      bg::correct(u);
      if (!bg::is_valid(u, reason)) return UnionFailed(polygons, group, field, reason);
    } catch (const std::exception& e) {
      return UnionFailed(polygons, group, field, e.what());
    }
    for (BPolygon& p : u) out.push_back(std::move(p));
  }
  return out;
}

}  // namespace covplan::geometry_internal
