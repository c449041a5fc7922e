// A robot whose own cell is reported blocked (it stands in the obstacle's
// cell) leaves it once and never comes back: which way it leaves decides
// what stays reachable. These maps are drawn one character per 0.8 m cell so
// the exits are known: the robot leaves into the larger side, never by a
// move that clips another reported cell, and says it is walled in
// (robot_cell_kept_free) when no clean move out exists.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/occupancy_map.h"
#include "planner/replan/replanner.h"
#include "planner/tour/grid_paths.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

constexpr double kCell = 0.8;  // tool width = one character
constexpr int kPixelsPerChar = 8;

// The plan of an ASCII map at a 0.8 m tool, kept as a server keeps it.
RetainedPlan PlanOf(const std::vector<std::string>& rows, std::optional<Pose2> start = {},
                    std::optional<Pose2> end = {}) {
  const int lines = static_cast<int>(rows.size());
  const int columns = static_cast<int>(rows[0].size());
  OccupancyMap map(columns * kPixelsPerChar, lines * kPixelsPerChar, kCell / kPixelsPerChar,
                   {0.0, 0.0});
  for (int r = 0; r < map.height(); ++r) {  // row 0 is the bottom
    for (int c = 0; c < map.width(); ++c) {
      const char ch = rows[lines - 1 - r / kPixelsPerChar][c / kPixelsPerChar];
      map.set(r, c, ch == '.' ? CellState::kFree : CellState::kOccupied);
    }
  }
  PlanOptions o;
  o.robot.tool_width_m = kCell;
  o.robot.start = start;
  o.robot.end = end;
  o.time_limit_s = 0.3;
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
  EXPECT_TRUE(r.ok()) << r.status();
  RetainedPlan old;
  old.plan = std::move(r->plan);
  old.area = std::move(r->area);
  old.request = o.ToRequest();
  return old;
}

// The centre of character (line, column) of a map of `lines` lines, in
// metres (the first line is the top of the picture).
Point2 CharCentre(int lines, int line, int column) {
  return {(column + 0.5) * kCell, (lines - 1 - line + 0.5) * kCell};
}

// The robot on the old path inside `cell` (5 cm or more from its borders:
// a robot on a border stands in the cell it came from), at the point of the
// path nearest to `near` (the path must visit the cell).
RobotProgress OnPathInCell(const RetainedPlan& old, CellIndex cell, Point2 near) {
  const Grid& g = *old.area->drive;
  const std::vector<Waypoint>& path = old.plan.path;
  RobotProgress at;
  double best = INFINITY;
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 a{path[i - 1].x, path[i - 1].y}, b{path[i].x, path[i].y};
    const int steps = std::max(1, static_cast<int>(std::hypot(b.x - a.x, b.y - a.y) / 0.005));
    for (int k = 1; k < steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const Point2 p{a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
      const double d = std::hypot(p.x - near.x, p.y - near.y);
      bool inside = true;
      for (const double dx : {-0.05, 0.05}) {
        for (const double dy : {-0.05, 0.05}) inside &= g.CellAt({p.x + dx, p.y + dy}) == cell;
      }
      if (!inside || d >= best) continue;
      best = d;
      at.waypoint = static_cast<int>(i);
      at.position = p;
    }
  }
  EXPECT_TRUE(at.position.has_value())
      << "the old path never enters (" << cell.row << ", " << cell.col << ")";
  return at;
}

// No segment of `path` touches `cell`.
bool PathTouches(const Grid& g, const std::vector<Waypoint>& path, CellIndex cell) {
  for (size_t i = 1; i < path.size(); ++i) {
    if (SegmentTouches(g, {path[i - 1].x, path[i - 1].y}, {path[i].x, path[i].y},
                       [&](int r, int c) { return r == cell.row && c == cell.col; })) {
      return true;
    }
  }
  return false;
}

// Whether some sweep of `plan` before (or, with before false, after)
// waypoint `w` covers `cell`.
bool SweptAround(const CoveragePlan& plan, int w, CellIndex cell, bool before) {
  for (const CoverageSweep& s : plan.sweeps) {
    if ((s.waypoint <= w) != before) continue;
    for (const CellIndex& c : s.cells) {
      if (c == cell) return true;
    }
  }
  return false;
}

// A room above, a one-cell corridor, and a two-cell pocket below. The robot
// starts in the pocket, sweeps it, and drives up the corridor to the room;
// near the pocket its cell is reported blocked. The nearest way out is back
// into the pocket, all swept; the room (24 cells) is all still to cover.
// Before: it left into the pocket and the room was cut off for good.
TEST(RobotCellExit, LeavesTowardsWhatIsLeftToCoverNotTheNearestCell) {
  const std::vector<std::string> rows = {
      "##########",  //
      "#........#",  //
      "#........#",  //
      "#........#",  //
      "####.#####",  //
      "####.#####",  //
      "####..####",  //
      "##########",  //
  };
  const int lines = static_cast<int>(rows.size());
  const Point2 pocket_far = CharCentre(lines, 6, 5), room_middle = CharCentre(lines, 2, 4);
  const RetainedPlan old = PlanOf(rows, Pose2{pocket_far.x, pocket_far.y, 0.0},
                                  Pose2{room_middle.x, room_middle.y, 0.0});
  const Grid& g = *old.area->drive;
  const CellIndex corridor = g.CellAt(CharCentre(lines, 5, 4));
  const CellIndex pocket = g.CellAt(pocket_far);
  const CellIndex room = g.CellAt(room_middle);
  ASSERT_TRUE(g.IsFree(corridor) && g.IsFree(pocket) && g.IsFree(room));
  // The robot in the corridor cell, as near to the pocket as the path comes.
  const Point2 border{
      g.CellCenter(corridor).x,
      (g.CellCenter(corridor).y + g.CellCenter(g.CellAt(CharCentre(lines, 6, 4))).y) / 2};
  const RobotProgress at = OnPathInCell(old, corridor, border);
  ASSERT_TRUE(at.position.has_value());
  ASSERT_LT(std::hypot(at.position->x - border.x, at.position->y - border.y), 0.2);
  ASSERT_TRUE(SweptAround(old.plan, at.waypoint, pocket, /*before=*/true));
  ASSERT_FALSE(SweptAround(old.plan, at.waypoint, room, /*before=*/true));
  Observations seen;
  seen.points = {g.CellCenter(corridor)};
  absl::StatusOr<ReplanResult> r = Replan(old, at, seen, ReplanOptions(), nullptr);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->stats.robot_cell_blocked);
  EXPECT_FALSE(r->stats.robot_cell_kept_free);
  const Grid& drive = *r->area->drive;
  EXPECT_FALSE(drive.IsFree(corridor));
  EXPECT_TRUE(drive.IsFree(room)) << "the room was cut off";
  EXPECT_FALSE(drive.IsFree(pocket));
  EXPECT_TRUE(SweptAround(r->plan, 0, room, /*before=*/false));
  EXPECT_EQ(testing::CheckPathStaysFree(drive, r->plan.path, /*may_leave_start_cell=*/true), "");
}

// The robot in the last cell of a dead end whose only other neighbour, a
// diagonal, is reached by clipping a cell reported blocked with it: no
// clean way out. It is walled in and says so; the plan never clips the
// reported cell (before: it left by that diagonal, through the obstacle).
TEST(RobotCellExit, NoMoveOutWithoutClippingAnObstacleIsWalledIn) {
  const std::vector<std::string> rows = {
      "#######",  //
      "#.....#",  //
      "#.....#",  //
      "#.#####",  //
      "#######",  //
  };
  const int lines = static_cast<int>(rows.size());
  const RetainedPlan old = PlanOf(rows);
  const Grid& g = *old.area->drive;
  const CellIndex dead_end = g.CellAt(CharCentre(lines, 3, 1));
  const CellIndex above = g.CellAt(CharCentre(lines, 2, 1));
  const CellIndex diagonal = g.CellAt(CharCentre(lines, 2, 2));
  ASSERT_TRUE(g.IsFree(dead_end) && g.IsFree(above) && g.IsFree(diagonal));
  const RobotProgress at = OnPathInCell(old, dead_end, g.CellCenter(dead_end));
  ASSERT_TRUE(at.position.has_value());
  Observations seen;
  seen.points = {g.CellCenter(dead_end), g.CellCenter(above)};
  for (ReplanMethod method : {ReplanMethod::kGreedyDetour, ReplanMethod::kIlp1, ReplanMethod::kAuto,
                              ReplanMethod::kFull}) {
    SCOPED_TRACE(ReplanMethodName(method));
    ReplanOptions options;
    options.method = method;
    absl::StatusOr<ReplanResult> r = Replan(old, at, seen, options, nullptr);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_TRUE(r->stats.robot_cell_kept_free);
    EXPECT_FALSE(r->area->drive->IsFree(above));
    EXPECT_FALSE(PathTouches(g, r->plan.path, above)) << "the plan clips the reported cell";
  }
}

}  // namespace
}  // namespace covplan
