#include "planner/stc/online_stc.h"

#include <cstdlib>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/stc/spanning_tree.h"
#include "planner/stc/stc_walk.h"

namespace covplan {

SubCellRobot::SubCellRobot(const Grid& truth, CellIndex start)
    : truth_(truth), at_(start), trail_{start}, marked_(truth.size(), 0) {}

absl::Status SubCellRobot::Step(CellIndex to) {
  const int dr = to.row - at_.row, dc = to.col - at_.col;
  if (std::abs(dr) + std::abs(dc) != 1 || !truth_.Passable(at_.row, at_.col, dr, dc)) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "the true grid blocks the move (%d, %d) -> (%d, %d)", at_.row, at_.col, to.row, to.col));
  }
  at_ = to;
  trail_.push_back(to);
  return absl::OkStatus();
}

uint8_t SubCellRobot::SenseFreeBits(const CoarseGrid& truth_coarse, int id) {
  ++sensor_reads_;
  return truth_coarse.free_bits(id);
}

absl::StatusOr<OnlineStcStats> RunOnlineStc(SubCellRobot* robot, PartialCells partial) {
  const Grid& truth = robot->truth();
  // What the sensor reads: the truth, seen through STC's coarse-cell rules.
  const CoarseGrid world(truth, truth, {0, 0}, partial);
  const CellIndex start = robot->at();
  const StcRoot root{world.CoarseOf(start), world.PositionOf(start)};
  if (!world.IsNode(root.cell)) {
    return absl::InvalidArgumentError(
        "on-line STC: the robot starts outside the coarse cells STC covers");
  }
  OnlineStcStats stats;
  // The robot's memory: the tree, the coarse cells sensed, the sub-cells known free.
  StcTree tree;
  tree.sides.assign(world.size(), 0);
  std::vector<uint8_t> seen(world.size(), 0), sensed(world.size(), 0),
      sensed_around(world.size(), 0);
  std::vector<uint8_t> known_free(truth.size(), 0);
  std::vector<CellIndex> known_cells;
  auto sense_around = [&](int id) {
    if (sensed_around[id]) return;
    sensed_around[id] = 1;
    for (int side = -1; side < 4; ++side) {
      const int n = side < 0 ? id : world.Neighbour(id, side);
      if (n < 0 || sensed[n]) continue;
      sensed[n] = 1;
      ++stats.max_stored_cells;
      const uint8_t bits = robot->SenseFreeBits(world, n);
      for (int p = 0; p < 4; ++p) {
        const CellIndex c = world.SubCell(n, p);
        if (!((bits >> p) & 1)) continue;
        known_free[truth.Index(c.row, c.col)] = 1;
        known_cells.push_back(c);
      }
    }
  };
  StcWalker::World w;
  w.may_enter = [&](CellIndex c) {
    return truth.InBounds(c.row, c.col) && known_free[truth.Index(c.row, c.col)];
  };
  // The sensor saw both cells, so it saw whether a wall stands between them.
  w.passable = [&](CellIndex c, int dr, int dc) { return truth.Passable(c.row, c.col, dr, dc); };
  w.to_cover = [&](CellIndex c) {
    return truth.IsFree(c) && (partial == PartialCells::kCover || world.IsNode(world.CoarseOf(c)));
  };
  w.orphan = [&](CellIndex c) { return world.IsOrphan(c); };
  w.on_step = [&](CellIndex c) -> absl::Status {
    RETURN_IF_ERROR(robot->Step(c));
    ++stats.steps;
    sense_around(world.CoarseOf(c));
    return absl::OkStatus();
  };
  seen[root.cell] = 1;
  sense_around(root.cell);
  StcWalker walker(truth, std::move(w), start);
  std::vector<CellIndex> deferred;
  StcRoot at = root;
  const StopToken never;
  while (true) {
    // DFS, one side at a time as the circumnavigation reaches it.
    if (!tree.HasEdge(at.cell, at.position)) {
      const int next = world.Neighbour(at.cell, at.position);
      if (next >= 0 && !seen[next] && world.CanLink(at.cell, at.position)) {
        seen[next] = 1;
        tree.sides[at.cell] |= 1 << at.position;
        tree.sides[next] |= 1 << ((at.position + 2) % 4);
        ++stats.tree_edges;
        sense_around(next);
      }
    }
    at = NextOnRing(world, tree, at);
    if (at.cell == root.cell && at.position == root.position) break;
    const CellIndex sub = world.SubCell(at.cell, at.position);
    if (!truth.IsFree(sub)) continue;
    // A sub-cell whose only known way in leads through cells not sensed
    // yet is left for later, when more is sensed.
    const absl::Status moved = walker.Visit(sub, never);
    if (absl::IsNotFound(moved)) {
      deferred.push_back(sub);
      ++stats.deferred_cells;
    } else {
      RETURN_IF_ERROR(moved);
    }
  }
  RETURN_IF_ERROR(walker.Excursions());
  // What is left: deferred tree cells and (kCover) orphans it knows of;
  // reaching them senses more, so repeat until nothing known is left.
  while (true) {
    std::vector<CellIndex> pending;
    for (const CellIndex& c : deferred) {
      if (!walker.covered(c)) pending.push_back(c);
    }
    if (partial == PartialCells::kCover) {
      for (const CellIndex& c : known_cells) {
        if (!walker.covered(c)) pending.push_back(c);
      }
    }
    if (pending.empty()) break;
    const absl::Status swept = walker.SweepRemaining(pending, never);
    if (absl::IsNotFound(swept))
      return absl::InternalError("on-line STC: a sensed cell cannot be reached");
    RETURN_IF_ERROR(swept);
  }
  const absl::Status back = walker.GoTo(start);
  if (absl::IsNotFound(back))
    return absl::InternalError("on-line STC: no known way back to the start");
  RETURN_IF_ERROR(back);
  return stats;
}

absl::StatusOr<OnlineStcStats> RunAntStc(SubCellRobot* robot) {
  const Grid& truth = robot->truth();
  const CoarseGrid world(truth, truth, {0, 0}, PartialCells::kDiscard);
  const CellIndex start = robot->at();
  // The robot's whole memory: the start cell and position, the current cell
  // and position, and the side it entered the current cell by.
  const int s = world.CoarseOf(start);
  const int k0 = world.PositionOf(start);
  if (!world.IsNode(s)) {
    return absl::InvalidArgumentError(
        "ant-like STC: the robot must start in a wholly free coarse cell");
  }
  int x = s, pos = k0, entry_side = (k0 + 3) % 4;
  OnlineStcStats stats;
  auto marked = [&](int cell, int p) { return robot->Marked(world.SubCell(cell, p)); };
  auto any_marked = [&](int cell) {
    for (int p = 0; p < 4; ++p) {
      if (marked(cell, p)) return true;
    }
    return false;
  };
  auto is_new = [&](int cell, int side) {
    const int y = world.Neighbour(cell, side);
    if (y < 0) return false;
    robot->SenseFreeBits(world, y);
    return world.CanLink(cell, side) && !any_marked(y);
  };
  // Parent(x): the side between the unmarked and the marked sub-cells, in
  // counter-clockwise order; the entry side while nothing of x is marked.
  auto parent_side = [&]() {
    if (!any_marked(x)) return entry_side;
    for (int e = 0; e < 4; ++e) {
      if (marked(x, e) && !marked(x, (e + 3) % 4)) return (e + 3) % 4;
    }
    return entry_side;  // all marked: never asked (the robot has left for good)
  };
  auto step = [&](CellIndex to) -> absl::Status {
    robot->MarkHere();  // a sub-cell is marked as the tool leaves it
    RETURN_IF_ERROR(robot->Step(to));
    ++stats.steps;
    return absl::OkStatus();
  };
  auto advance_to = [&](int target) -> absl::Status {
    while (pos != target) {
      pos = (pos + 1) % 4;
      RETURN_IF_ERROR(step(world.SubCell(x, pos)));
    }
    return absl::OkStatus();
  };
  auto cross = [&](int side) -> absl::Status {
    RETURN_IF_ERROR(advance_to(side));
    const int y = world.Neighbour(x, side);
    RETURN_IF_ERROR(step(world.SubCell(y, (side + 3) % 4)));
    x = y;
    pos = (side + 3) % 4;
    entry_side = (side + 2) % 4;
    return absl::OkStatus();
  };
  while (true) {
    // The start cell scans all four sides from where the robot began; any
    // other cell the three after its parent.
    const int first = x == s ? k0 : (parent_side() + 1) % 4;
    const int count = x == s ? 4 : 3;
    int child = -1;
    for (int i = 0; i < count && child < 0; ++i) {
      const int side = (first + i) % 4;
      if (is_new(x, side)) child = side;
    }
    if (child >= 0) {
      RETURN_IF_ERROR(cross(child));
      ++stats.tree_edges;
    } else if (x != s) {
      RETURN_IF_ERROR(cross(parent_side()));
    } else {
      // Done: close the tour around the start cell (unless the robot came
      // back into its first sub-cell with the others all marked).
      bool others_marked = true;
      for (int p = 0; p < 4; ++p) others_marked = others_marked && (p == pos || marked(s, p));
      if (pos != k0 || !others_marked) {
        RETURN_IF_ERROR(advance_to((k0 + 3) % 4));
        RETURN_IF_ERROR(step(world.SubCell(s, k0)));
      }
      break;
    }
  }
  return stats;
}

}  // namespace covplan
