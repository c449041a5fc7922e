// The least turning of a drive path that must go around a blocked cell
// (docs/fleet.md, "Detours"). When the straight segment from a to b runs
// through a blocked cell at x0, every path from a to b on the drive grid's
// free cells crosses the line through x0 perpendicular to ab, and it
// crosses it outside the stretch of blocked cells around x0. A path of
// straight segments and turns in place through a point p turns at least
//   g(p) = min(HC(ha, A) + HC(A, B) + HC(B, hb),
//              HC(ha, A) + 2 pi - HC(A, hb),
//              2 pi - HC(ha, B) + HC(B, hb),  2 pi),
// with A = dir(a, p), B = dir(p, b) and HC the heading change. The turning
// before p walks from ha through the headings of the segments from a to p,
// whose positive sum is p - a: either they lie within half a turn and the
// walk passes A (it lies between them), or that part of the walk covers
// more than half a turn. Likewise after p for B. A walk between two
// headings it passes costs at least their heading change; a walk from x to
// y that covers more than half a turn costs at least 2 pi - HC(x, y) (it
// reaches both ends of an arc longer than half a turn). The four cases
// (both pass; the part after p covers; the part before p covers; both
// cover) give the four terms. The bound is g's least value over the
// crossing points, found on a fine angular sampling with each piece's
// Lipschitz margin taken off.
//
//   double t = DetourTurnBound(drive, a, ha, b, hb, 12 * drive.cell_size());
//
// Thread-safety: reentrant.
#ifndef COVPLAN_PLANNER_FLEET_DETOUR_TURN_H_
#define COVPLAN_PLANNER_FLEET_DETOUR_TURN_H_

#include "planner/grid/grid.h"

namespace covplan {

// Radians, in [0, 2 pi]; 0 when the segment ab is longer than `max_length`,
// when a or b is not in a free cell, or when no blocked cell on ab is found.
double DetourTurnBound(const Grid& drive, Point2 a, double ha, Point2 b, double hb,
                       double max_length);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_FLEET_DETOUR_TURN_H_
