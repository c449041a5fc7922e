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

}  // namespace covplan::geometry_internal
