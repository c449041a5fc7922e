#include "planner/replan/remainder.h"

#include <cmath>
#include <optional>
#include <utility>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"

namespace covplan::replan_internal {
namespace {

// Where a robot whose own cell was reported blocked leaves it: an adjacent
// cell free on `all` (the old drive grid less the blocked cells) that the
// straight move from `probe` reaches touching no other blocked cell (a
// reported obstacle is never clipped) and the robot's cell allows on the
// old drive grid (no thin wall, no cut corner), into the component the blocking
// leaves with the most cells still to cover (on `cover`, not `covered`
// before the robot: it cannot
// come back through its cell, so the others are cut off and lose the
// least), nearest first among equals. None: the robot is walled in.
std::optional<CellIndex> ExitCell(const Grid& old_drive, const Grid& all, Point2 probe,
                                  const Grid& cover, const std::vector<uint8_t>& covered) {
  int32_t num = 0;
  const std::vector<int32_t> comp = FreeComponents(all, &num);
  std::vector<int64_t> size(static_cast<size_t>(num), 0);
  for (size_t i = 0; i < comp.size(); ++i) {
    if (comp[i] >= 0 && cover.free_flags()[i] && !covered[i]) ++size[comp[i]];
  }
  const CellIndex own = all.CellAt(probe);
  // The robot's cell was free on the old drive grid: its moves there (thin
  // walls, corners, obstacle pixels: DriveMoveMask) bound the ways out too.
  const uint8_t moves = old_drive.IsFree(own) ? DriveMoveMask(old_drive, own) : 0xff;
  auto allowed = [&](int dr, int dc) {
    for (int k = 0; k < 8; ++k) {
      if (kDriveDr[k] == dr && kDriveDc[k] == dc) return ((moves >> k) & 1) != 0;
    }
    return false;
  };
  std::optional<CellIndex> best;
  int64_t best_size = 0;
  double best_d2 = 0.0;
  for (int dr = -1; dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      const CellIndex n{own.row + dr, own.col + dc};
      if ((dr == 0 && dc == 0) || !all.IsFree(n) || !allowed(dr, dc) ||
          !ClearJoin(all, {probe.x, probe.y, 0}, n))
        continue;
      const int64_t s = size[comp[all.Index(n.row, n.col)]];
      const Point2 q = all.CellCenter(n);
      const double d2 = (q.x - probe.x) * (q.x - probe.x) + (q.y - probe.y) * (q.y - probe.y);
      if (!best || s > best_size || (s == best_size && d2 < best_d2)) {
        best = n, best_size = s, best_d2 = d2;
      }
    }
  }
  return best;
}

// The free flags of the new drive grid: the old drive grid less the `blocked`
// cells, cut to the component of the robot at `robot_cell` (`probe` is where
// it stands, for finding its way out of a blocked cell; `cover` less
// `covered` is what is left to cover, for choosing that way).
std::vector<uint8_t> NewDriveFlags(const Grid& old_drive, CellIndex robot_cell, Point2 probe,
                                   const Grid& cover, const std::vector<uint8_t>& covered,
                                   std::vector<uint8_t>* blocked, ReplanStats* st) {
  std::vector<uint8_t> free = old_drive.free_flags();
  for (size_t i = 0; i < free.size(); ++i) {
    st->newly_blocked_cells += (*blocked)[i];
    if ((*blocked)[i]) free[i] = 0;
  }
  // The robot's own cell reported blocked (it stands in the obstacle's
  // cell): blocked for the rest of the mission, like a dock's cell, which
  // the robot leaves by its first move (ExitCell). Only a robot walled in
  // keeps its cell (and says so).
  CellIndex keep_cell = robot_cell;
  if ((*blocked)[old_drive.Index(robot_cell.row, robot_cell.col)]) {
    const std::optional<CellIndex> exit =
        ExitCell(old_drive, old_drive.WithFreeFlags(free), probe, cover, covered);
    if (exit) {
      keep_cell = *exit;
      st->robot_cell_blocked = true;
    } else {
      const int64_t i = old_drive.Index(robot_cell.row, robot_cell.col);
      (*blocked)[i] = 0, free[i] = 1, --st->newly_blocked_cells;
      st->robot_cell_kept_free = true;
    }
  }
  const Grid kept = old_drive.WithFreeFlags(free);
  int32_t num = 0;
  const std::vector<int32_t> comp = FreeComponents(kept, &num);
  const int32_t keep = comp[kept.Index(keep_cell.row, keep_cell.col)];
  for (size_t i = 0; i < free.size(); ++i) free[i] = free[i] && comp[i] == keep;
  return free;
}

// The old end (a dock) blocked or cut off by the new obstacles: the new plan
// ends at the reachable cell nearest to it instead, and says so.
void MoveEndIfCutOff(const Grid& old_drive, const Grid& drive, Pose2* end, ReplanStats* st) {
  const CellIndex end_cell = drive.CellAt({end->x, end->y});
  const bool end_newly_closed = old_drive.IsFree(end_cell) && !drive.IsFree(end_cell);
  if (!end_newly_closed && JoinCell(drive, *end, "end").ok()) return;
  // The distance is measured from `*end` as it moves to each nearer cell,
  // not from the old end: the choice the replanner has always made, kept so
  // that its plans stay the same.
  double best = INFINITY;
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (!drive.free_flags()[i]) continue;
    const Point2 p = drive.CellCenter(drive.FromIndex(i));
    const double d = std::hypot(p.x - end->x, p.y - end->y);
    if (d < best) best = d, *end = Pose2{p.x, p.y, end->theta};
  }
  st->end_moved = true;
}

// Per cell: still to sweep (to cover on the old plan, not swept before the
// robot) and reachable on `drive`; the cells cut off go to `out->unreachable`.
std::vector<uint8_t> CellsToCover(const Grid& old_cover, const Grid& drive,
                                  const std::vector<uint8_t>& blocked,
                                  const std::vector<uint8_t>& covered, ReplanResult* out) {
  ReplanStats& st = out->stats;
  std::vector<uint8_t> to_cover(drive.free_flags().size(), 0);
  for (size_t i = 0; i < to_cover.size(); ++i) {
    const bool was = old_cover.free_flags()[i] && !covered[i];
    st.covered_cells_before += old_cover.free_flags()[i] && covered[i];
    if (!was) continue;
    if (blocked[i]) {
      ++st.newly_obstructed_cells;
      continue;
    }
    if (drive.free_flags()[i]) {
      to_cover[i] = 1;
      ++st.remaining_cells;
    } else {
      ++st.newly_unreachable_cells;
      out->unreachable.push_back(drive.FromIndex(static_cast<int64_t>(i)));
    }
  }
  st.remaining_free_area_m2 = st.remaining_cells * drive.cell_size() * drive.cell_size();
  return to_cover;
}

}  // namespace

absl::StatusOr<Remainder> ComputeRemainder(const RetainedPlan& old, const RobotProgress& progress,
                                           const Observations& observations, ReplanResult* out) {
  Remainder rest;
  rest.old = &old;
  rest.old_oarp = old.plan.detail_as<OarpDetail>();
  rest.robot = old.request.common.robot;
  const Grid& old_drive = *old.area->drive;
  ASSIGN_OR_RETURN(rest.at, Locate(old.plan, progress));
  // The robot's cell, or (at a dock in a cell that is not free) the free cell
  // its path joins the grid at.
  // Probed a hair behind the robot along its segment: a robot exactly on a
  // cell border stands in the cell it came from, not in the one ahead (which
  // a new obstacle may block).
  const Point2 probe{rest.at.at.x - 1e-6 * std::cos(rest.at.heading),
                     rest.at.at.y - 1e-6 * std::sin(rest.at.heading)};
  absl::StatusOr<CellIndex> joined = JoinCell(old_drive, Pose2{probe.x, probe.y, 0}, "robot");
  if (!joined.ok()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("progress: the robot at (%.3f, %.3f) is neither in nor next to a free cell "
                        "of the plan's grid",
                        rest.at.at.x, rest.at.at.y));
  }
  ASSIGN_OR_RETURN(std::vector<uint8_t> blocked, BlockedCells(old_drive, observations));
  std::vector<uint8_t> covered;
  rest.legs = RemainingLegs(old.plan, rest.at, &covered);
  const Waypoint& last = old.plan.path.back();
  rest.end = Pose2{last.x, last.y, last.theta};

  ReplanStats& st = out->stats;
  rest.drive = std::make_shared<const Grid>(old_drive.WithFreeFlags(
      NewDriveFlags(old_drive, *joined, probe, *old.area->cover, covered, &blocked, &st)));
  const Grid& drive = *rest.drive;
  MoveEndIfCutOff(old_drive, drive, &rest.end, &st);
  rest.to_cover = CellsToCover(*old.area->cover, drive, blocked, covered, out);
  auto area = std::make_shared<CoverageArea>(*old.area);
  area->drive = rest.drive;
  area->cover = std::make_shared<const Grid>(old_drive.WithFreeFlags(rest.to_cover));
  area->cover_cells = st.remaining_cells;
  area->unreachable_cells = old.area->unreachable_cells + st.newly_unreachable_cells;
  out->area = std::move(area);
  return rest;
}

}  // namespace covplan::replan_internal
