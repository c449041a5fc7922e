#include "planner/replan/replanner.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/push_relabel_partitioner.h"
#include "planner/replan/rank_replan.h"
#include "planner/replan/replan_walk.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/path_timing.h"
#include "planner/tour/polyline_tour.h"

namespace covplan {
namespace {

using replan_internal::GreedyWalk;
using replan_internal::Leg;
using replan_internal::Walk;

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

// Drive time of a path under the robot model (the robot turns in place to
// each waypoint's heading, then drives straight): the same rule as the plan
// statistics.
double PathTime(const std::vector<Waypoint>& path, const RobotModel& robot) {
  return ComputePathStats(path, robot).estimated_duration_s;
}

int64_t Ilp1Columns(const Grid& w) {
  int64_t cols = 6 * w.CountFree();
  auto run_sum = [&](bool horizontal) {
    for (int outer = 0; outer < (horizontal ? w.rows() : w.cols()); ++outer) {
      int64_t run = 0;
      for (int inner = 0; inner < (horizontal ? w.cols() : w.rows()); ++inner) {
        const int r = horizontal ? outer : inner, c = horizontal ? inner : outer;
        const bool linked = run > 0 && (horizontal ? w.LeftLinked(r, c) : w.BelowLinked(r, c));
        if (!w.IsFree(r, c)) {
          cols += run * (run + 1) / 2, run = 0;
          continue;
        }
        if (run > 0 && !linked) cols += run * (run + 1) / 2, run = 0;
        ++run;
      }
      cols += run * (run + 1) / 2;
    }
  };
  run_sum(true);
  run_sum(false);
  return cols;
}

// The state shared by the methods: the old plan, where the robot is, the
// remainder's grids.
struct Context {
  const RetainedPlan* old = nullptr;
  const OarpDetail* old_oarp = nullptr;
  RobotModel robot;
  replan_internal::Located at;
  std::vector<Leg> legs;
  std::shared_ptr<const Grid> drive;  // old drive minus new obstacles, the robot's component
  std::vector<uint8_t> remaining;     // cells still to cover, reachable
  std::shared_ptr<const CoverageArea> area;
  std::vector<CellIndex> unreachable;
  Pose2 end;
};

// Elements of TOUR-REPLAN for a new partition `ranks` (with is_new flags):
// the maximal unchanged sections of the old path after `walk` stopped whose
// coverage segments are all kept ranks, and every other rank on its own.
std::vector<PolylineElement> TourElements(const Context& c, const Walk& walk,
                                          const std::vector<Rank>& ranks,
                                          const std::vector<bool>& is_new, ReplanStats* stats) {
  const Grid& drive = *c.drive;
  const CoveragePlan& old = c.old->plan;
  std::map<std::tuple<int, int, int, int, int>, int> kept;  // rank -> index in `ranks`
  for (size_t r = 0; r < ranks.size(); ++r) {
    if (is_new[r]) continue;
    const Rank& k = ranks[r];
    kept[{static_cast<int>(k.orientation), k.first.row, k.first.col, k.last.row, k.last.col}] =
        static_cast<int>(r);
  }
  auto kept_index = [&](int old_segment) -> int {
    const int tag = old.path[old_segment].rank;
    if (c.old_oarp == nullptr || tag < 0 || tag >= static_cast<int>(c.old_oarp->ranks.size()))
      return -1;
    const Rank& k = c.old_oarp->ranks[tag];
    auto it = kept.find(
        {static_cast<int>(k.orientation), k.first.row, k.first.col, k.last.row, k.last.col});
    return it == kept.end() ? -1 : it->second;
  };
  const Grid& old_drive = *c.old->area->drive;
  auto closed = [&](int r, int col) {
    return !drive.InBounds(r, col) || (old_drive.IsFree(r, col) && !drive.IsFree(r, col));
  };
  auto segment_clear = [&](int i) {
    const Waypoint& a = old.path[i - 1];
    const Waypoint& b = old.path[i];
    return !replan_internal::SegmentTouches(drive, {a.x, a.y}, {b.x, b.y}, closed);
  };
  std::vector<bool> used(ranks.size(), false);
  std::vector<PolylineElement> elements;
  std::map<int, const CoverageSweep*> sweep_at;
  for (const CoverageSweep& s : old.sweeps) sweep_at[s.waypoint] = &s;
  // Old segments strictly after the leg the walk stopped on.
  const int first = walk.end_leg >= 0 && walk.end_leg < static_cast<int>(c.legs.size())
                        ? c.legs[walk.end_leg].old_segment + 1
                        : static_cast<int>(old.path.size());
  PolylineElement piece;
  int last_coverage = -1;  // number of segments in `piece` up to its last kept coverage segment
  auto close_piece = [&] {
    if (last_coverage > 0) {
      piece.points.resize(last_coverage + 1);
      piece.kinds.resize(last_coverage);
      piece.sweeps.resize(last_coverage);
      piece.tags.resize(last_coverage);
      piece.last_cell = drive.CellAt(piece.points.back());
      piece.kind = TourElementKind::kPathPiece;
      double len = 0;
      for (size_t k = 1; k < piece.points.size(); ++k) {
        len += std::hypot(piece.points[k].x - piece.points[k - 1].x,
                          piece.points[k].y - piece.points[k - 1].y);
      }
      ++stats->kept_path_pieces;
      stats->kept_path_m += len;
      elements.push_back(std::move(piece));
    }
    piece = PolylineElement();
    last_coverage = -1;
  };
  for (int i = first; i < static_cast<int>(old.path.size()); ++i) {
    const Waypoint& wb = old.path[i];
    const bool coverage = wb.kind == SegmentKind::kCoverage;
    const int r = coverage ? kept_index(i) : -1;
    const bool usable = segment_clear(i) && (!coverage || (r >= 0 && !used[r]));
    if (!usable || (piece.points.empty() && !coverage)) {
      close_piece();
      continue;
    }
    if (piece.points.empty()) {
      const Waypoint& wa = old.path[i - 1];
      piece.points.push_back({wa.x, wa.y});
      piece.first_cell = drive.CellAt({wa.x, wa.y});
    }
    piece.points.push_back({wb.x, wb.y});
    piece.kinds.push_back(wb.kind);
    auto sw = sweep_at.find(i);
    piece.sweeps.push_back(coverage && sw != sweep_at.end() ? sw->second->cells
                                                            : std::vector<CellIndex>{});
    piece.tags.push_back(coverage ? r : -1);
    if (coverage) {
      used[r] = true;
      last_coverage = static_cast<int>(piece.kinds.size());
    }
  }
  close_piece();
  for (size_t r = 0; r < ranks.size(); ++r) {
    if (used[r]) continue;
    elements.push_back(RankElement(drive, ranks[r].first, ranks[r].last, static_cast<int>(r)));
  }
  return elements;
}

}  // namespace

const char* ReplanMethodName(ReplanMethod m) {
  switch (m) {
    case ReplanMethod::kAuto:
      return "auto";
    case ReplanMethod::kIlp1:
      return "ilp1";
    case ReplanMethod::kIlp2:
      return "ilp2";
    case ReplanMethod::kGreedyDetour:
      return "greedy_detour";
    case ReplanMethod::kFull:
      return "full";
  }
  return "unknown";
}

namespace {

// Appends transitions from `from` to `to` over `drive` (false when stopped).
absl::StatusOr<bool> AppendRoute(const Grid& drive, Point2 from, const Pose2& to,
                                 const StopToken& stop, std::vector<Waypoint>* path) {
  if (std::hypot(from.x - to.x, from.y - to.y) < kMinSegmentM) return true;
  ASSIGN_OR_RETURN(CellIndex a, JoinCell(drive, Pose2{from.x, from.y, 0}, "start"));
  ASSIGN_OR_RETURN(CellIndex b, JoinCell(drive, to, "end"));
  AnyAngleSearch search(drive);
  if (!search.Run(a, stop)) return false;
  std::vector<Point2> pts;
  for (const CellIndex& cell : search.PathTo(b)) pts.push_back(drive.CellCenter(cell));
  pts.push_back({to.x, to.y});
  Point2 at = from;
  for (const Point2& p : pts) {
    if (std::hypot(p.x - at.x, p.y - at.y) < kMinSegmentM) continue;
    path->push_back({p.x, p.y, std::atan2(p.y - at.y, p.x - at.x), SegmentKind::kTransition, -1});
    at = p;
  }
  return true;
}

// Joins the walk's prefix (robot -> tour start) and the tour path.
void Append(const std::vector<Waypoint>& tour, const std::vector<CoverageSweep>& tour_sweeps,
            CoveragePlan* plan) {
  const int offset = static_cast<int>(plan->path.size()) - 1;  // tour[0] is the prefix's end
  for (size_t i = 1; i < tour.size(); ++i) plan->path.push_back(tour[i]);
  for (const CoverageSweep& s : tour_sweeps) plan->sweeps.push_back({s.waypoint + offset, s.cells});
}

// TOUR-REPLAN from the end of `walk` over `ranks`; false when the time ran out.
absl::StatusOr<bool> TourReplan(const Context& c, const Walk& walk, const std::vector<Rank>& ranks,
                                const std::vector<bool>& is_new, const ReplanOptions& options,
                                const StopToken& stop, double tour_budget_s, ReplanResult* out) {
  std::vector<PolylineElement> elements = TourElements(c, walk, ranks, is_new, &out->stats);
  if (elements.empty()) {
    // Nothing left to cover after the prefix: drive on to the old end.
    ASSIGN_OR_RETURN(bool routed, AppendRoute(*c.drive, walk.end, c.end, stop, &out->plan.path));
    if (!routed) return false;
    out->plan.termination = Termination::Converged("nothing left to cover: drive to the end");
    return true;
  }
  const absl::Time t0 = absl::Now();
  absl::StatusOr<PolylineTourModel> model = PolylineTourModel::Create(
      *c.drive, std::move(elements), Pose2{walk.end.x, walk.end.y, walk.end_heading}, c.end,
      std::make_shared<const TravelTimeCost>(c.robot), stop, options.num_threads);
  if (!model.ok()) {
    if (absl::IsDeadlineExceeded(model.status()) || absl::IsCancelled(model.status())) return false;
    return model.status();
  }
  out->stats.transitions_ms = model->transitions_ms();
  const absl::Time t1 = absl::Now();
  OrdererOptions oo;
  oo.time_limit_s = std::max(
      1e-3, std::min(options.tour_time_limit_s, tour_budget_s - absl::ToDoubleSeconds(t1 - t0)));
  oo.seed = options.seed;
  oo.num_threads = options.num_threads;
  absl::StatusOr<TourOrder> order = GtspOrderer(oo).Order(*model, stop);
  if (!order.ok()) {
    if (absl::IsDeadlineExceeded(order.status()) || absl::IsCancelled(order.status())) return false;
    return order.status();
  }
  out->stats.tour_ms = MsSince(t1);
  std::vector<Waypoint> tour;
  std::vector<CoverageSweep> sweeps;
  model->BuildPath(order->vertices, &tour, &sweeps);
  Append(tour, sweeps, &out->plan);
  out->plan.termination = order->termination;
  return true;
}

}  // namespace

absl::StatusOr<ReplanResult> Replan(const RetainedPlan& old, const RobotProgress& progress,
                                    const Observations& observations, const ReplanOptions& options,
                                    ReplanEstimator* estimator) {
  const absl::Time start = absl::Now();
  if (old.area == nullptr || old.plan.grid == nullptr || old.area->drive == nullptr) {
    return absl::FailedPreconditionError("the plan has no coverage area to replan on");
  }
  // A battery plan (or a greedy replan of one, which keeps its station legs
  // but not its cycle table): only the greedy detour keeps the station legs.
  // The ILP methods and kFull re-tour the remainder without charge stops, and
  // the battery state at the robot is not known here to split it again.
  const bool battery_plan =
      !old.plan.cycles.empty() ||
      std::any_of(old.plan.path.begin(), old.plan.path.end(), [](const Waypoint& w) {
        return w.kind == SegmentKind::kToStation || w.kind == SegmentKind::kFromStation;
      });
  if (battery_plan && options.method != ReplanMethod::kGreedyDetour) {
    return absl::FailedPreconditionError(
        absl::StrFormat("a battery plan (charge cycles) can only be replanned with method "
                        "greedy_detour, got %s: the other "
                        "methods would drop its station legs; plan again with the battery",
                        ReplanMethodName(options.method)));
  }
  Context c;
  c.old = &old;
  c.old_oarp = old.plan.detail_as<OarpDetail>();
  c.robot = old.request.common.robot;
  const Grid& old_drive = *old.area->drive;
  ASSIGN_OR_RETURN(c.at, replan_internal::Locate(old.plan, progress));
  // The robot's cell, or (at a dock in a cell that is not free) the free cell
  // its path joins the grid at.
  // Probed a hair behind the robot along its segment: a robot exactly on a
  // cell border stands in the cell it came from, not in the one ahead (which
  // a new obstacle may block).
  const Point2 probe{c.at.at.x - 1e-6 * std::cos(c.at.heading),
                     c.at.at.y - 1e-6 * std::sin(c.at.heading)};
  absl::StatusOr<CellIndex> joined = JoinCell(old_drive, Pose2{probe.x, probe.y, 0}, "robot");
  if (!joined.ok()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("progress: the robot at (%.3f, %.3f) is neither in nor next to a free cell "
                        "of the plan's grid",
                        c.at.at.x, c.at.at.y));
  }
  const CellIndex robot_cell = *joined;
  ASSIGN_OR_RETURN(std::vector<uint8_t> blocked,
                   replan_internal::BlockedCells(old_drive, observations));
  std::vector<uint8_t> covered;
  c.legs = replan_internal::RemainingLegs(old.plan, c.at, &covered);
  const Waypoint& last = old.plan.path.back();
  c.end = Pose2{last.x, last.y, last.theta};

  ReplanResult out;
  ReplanStats& st = out.stats;
  // The new drive grid: the old one less the new obstacles, the robot's component.
  std::vector<uint8_t> free = old_drive.free_flags();
  for (size_t i = 0; i < free.size(); ++i) {
    st.newly_blocked_cells += blocked[i];
    if (blocked[i]) free[i] = 0;
  }
  {
    const Grid all = old_drive.WithFreeFlags(free);
    // The robot's own cell reported blocked (it stands in the obstacle's
    // cell): blocked for the rest of the mission, like a dock's cell, which
    // the robot leaves by its first move to the nearest free neighbour. Only
    // a robot walled in on every side keeps its cell (and says so).
    CellIndex keep_cell = robot_cell;
    if (blocked[old_drive.Index(robot_cell.row, robot_cell.col)]) {
      absl::StatusOr<CellIndex> exit = JoinCell(all, Pose2{probe.x, probe.y, 0}, "robot");
      if (exit.ok()) {
        keep_cell = *exit;
        st.robot_cell_blocked = true;
      } else {
        const int64_t i = old_drive.Index(robot_cell.row, robot_cell.col);
        blocked[i] = 0, free[i] = 1, --st.newly_blocked_cells;
        st.robot_cell_kept_free = true;
      }
    }
    const Grid kept = old_drive.WithFreeFlags(free);
    int32_t num = 0;
    const std::vector<int32_t> comp = FreeComponents(kept, &num);
    const int32_t keep = comp[kept.Index(keep_cell.row, keep_cell.col)];
    for (size_t i = 0; i < free.size(); ++i) free[i] = free[i] && comp[i] == keep;
  }
  c.drive = std::make_shared<const Grid>(old_drive.WithFreeFlags(free));
  const Grid& drive = *c.drive;
  const CellIndex end_cell = drive.CellAt({c.end.x, c.end.y});
  const bool end_newly_closed = old_drive.IsFree(end_cell) && !drive.IsFree(end_cell);
  if (end_newly_closed || !JoinCell(drive, c.end, "end").ok()) {
    // The old end (a dock) is blocked or cut off by the new obstacles: end at
    // the reachable cell nearest to it instead, and say so.
    double best = INFINITY;
    for (int64_t i = 0; i < drive.size(); ++i) {
      if (!free[i]) continue;
      const Point2 p = drive.CellCenter(drive.FromIndex(i));
      const double d = std::hypot(p.x - c.end.x, p.y - c.end.y);
      if (d < best) best = d, c.end = Pose2{p.x, p.y, c.end.theta};
    }
    st.end_moved = true;
  }
  std::vector<uint8_t> to_cover(free.size(), 0);
  for (size_t i = 0; i < free.size(); ++i) {
    const bool was = old.area->cover->free_flags()[i] && !covered[i];
    st.covered_cells_before += old.area->cover->free_flags()[i] && covered[i];
    if (!was) continue;
    if (blocked[i]) {
      ++st.newly_obstructed_cells;
      continue;
    }
    if (free[i]) {
      to_cover[i] = 1;
      ++st.remaining_cells;
    } else {
      ++st.newly_unreachable_cells;
      out.unreachable.push_back(drive.FromIndex(static_cast<int64_t>(i)));
    }
  }
  st.remaining_free_area_m2 = st.remaining_cells * drive.cell_size() * drive.cell_size();
  auto area = std::make_shared<CoverageArea>(*old.area);
  area->drive = c.drive;
  area->cover = std::make_shared<const Grid>(old_drive.WithFreeFlags(to_cover));
  area->cover_cells = st.remaining_cells;
  area->unreachable_cells = old.area->unreachable_cells + st.newly_unreachable_cells;
  c.area = area;
  out.area = area;

  out.plan.planner = "oarp-replan";
  out.plan.grid = c.drive;
  // GREEDY_DETOUR over everything, computed first (it is cheap): the answer
  // whenever nothing better is ready in time.
  const Walk whole = GreedyWalk(old_drive, drive, c.legs, c.at.at, c.at.heading);
  st.num_encounters = whole.encounters;
  auto greedy = [&]() {
    out.plan.path = whole.path;
    out.plan.sweeps = whole.sweeps;
    // A walk that ended inside a blocked stretch (the old end cut off) still
    // drives to the (moved) end; the route is short and needs no deadline.
    AppendRoute(drive, whole.end, c.end, StopToken(), &out.plan.path).IgnoreError();
    st.greedy_detours.clear();
    for (int k = 0; k < whole.encounters; ++k) st.greedy_detours.push_back(k);
    st.replanned_encounter = -1;
    st.time_to_encounter_s = 0.0;
    st.rank_budget = -1;
    st.new_ranks = st.kept_ranks = st.kept_path_pieces = 0;
    st.kept_path_m = 0.0;
    st.method = ReplanMethodName(ReplanMethod::kGreedyDetour);
    out.plan.termination = Termination::Converged("greedy detour: no search");
    out.plan.detail = old.plan.detail;  // whole coverage legs keep their rank tags
  };
  // The call's own deadline, less the time kept for building the reply.
  const StopToken call_stop =
      options.stop.has_deadline()
          ? options.stop.WithEarlierDeadline(options.stop.deadline() -
                                             absl::Seconds(options.safety_margin_s))
          : options.stop;

  if (options.method == ReplanMethod::kGreedyDetour || whole.encounters == 0) {
    greedy();
    if (whole.encounters == 0) st.method = "unchanged";
  } else if (options.method == ReplanMethod::kFull) {
    // OARP-Original: a new partition of everything left, toured from the robot.
    st.method = ReplanMethodName(ReplanMethod::kFull);
    const Grid w = old_drive.WithFreeFlags(to_cover);
    const absl::Time t0 = absl::Now();
    std::vector<Rank> ranks;
    if (st.remaining_cells > 0) {
      absl::StatusOr<RankPartition> p = PushRelabelPartitioner().Partition(w, call_stop);
      if (!p.ok() && !absl::IsDeadlineExceeded(p.status()) && !absl::IsCancelled(p.status())) {
        return p.status();
      }
      if (p.ok()) ranks = std::move(p->ranks);
      if (!p.ok()) ranks.clear();
    }
    st.rank_replan_ms = MsSince(t0);
    st.new_ranks = static_cast<int64_t>(ranks.size());
    Walk at_robot;
    at_robot.path = {{c.at.at.x, c.at.at.y, c.at.heading, SegmentKind::kStart, -1}};
    at_robot.end = c.at.at;
    at_robot.end_heading = c.at.heading;
    at_robot.end_leg = static_cast<int>(c.legs.size());  // no old sections kept
    out.plan.path = at_robot.path;
    out.plan.sweeps.clear();
    auto detail = std::make_shared<OarpDetail>();
    detail->ranks = ranks;
    out.plan.detail = detail;
    const std::vector<bool> all_new(ranks.size(), true);
    bool done = false;
    if (!call_stop.ShouldStop() && !(ranks.empty() && st.remaining_cells > 0)) {
      ASSIGN_OR_RETURN(done,
                       TourReplan(c, at_robot, ranks, all_new, options, call_stop, 30.0, &out));
    }
    if (!done) greedy();
  } else {
    // Algorithm 1: encounters in path order, each with the budget its
    // time-to-reach allows.
    bool done = false;
    for (int k = 0; k < whole.encounters && !done && !call_stop.ShouldStop(); ++k) {
      const Walk prefix = whole.Prefix(k, drive);
      // Per-attempt figures start afresh (a failed attempt leaves none behind).
      st.new_ranks = st.kept_ranks = st.kept_path_pieces = 0;
      st.kept_path_m = st.rank_replan_ms = st.transitions_ms = st.tour_ms = 0.0;
      st.rank_lp_integral = true;
      const double tau = PathTime(prefix.path, c.robot);
      const double budget_s =
          tau - options.safety_margin_s - absl::ToDoubleSeconds(absl::Now() - start);
      const StopToken stop =
          call_stop.WithEarlierDeadline(absl::Now() + absl::Seconds(std::max(0.0, budget_s)));
      // Without an estimator the budget is unlimited (the time limit still holds).
      const int64_t m_bar =
          estimator != nullptr ? estimator->Budget(0.7 * budget_s) : RankReplanInput::kUnlimited;
      if (budget_s <= 0 || (estimator != nullptr && m_bar < 0) || stop.ShouldStop()) {
        st.greedy_detours.push_back(k);
        continue;
      }
      std::vector<uint8_t> wk = to_cover;
      for (size_t i = 0; i < wk.size(); ++i) wk[i] = wk[i] && !prefix.swept[i];
      const Grid w = old_drive.WithFreeFlags(wk);
      RankReplanInput in;
      in.cells = &w;
      if (c.old_oarp != nullptr) in.old_ranks = c.old_oarp->ranks;
      in.budget = m_bar;
      RankReplanMethod method =
          options.method == ReplanMethod::kIlp1 ? RankReplanMethod::kIlp1
          : options.method == ReplanMethod::kIlp2
              ? RankReplanMethod::kIlp2
              : (Ilp1Columns(w) <= options.ilp1_max_columns ? RankReplanMethod::kIlp1
                                                            : RankReplanMethod::kIlp2);
      const absl::Time t0 = absl::Now();
      std::vector<Rank> ranks;
      std::vector<bool> is_new;
      if (w.CountFree() > 0) {
        absl::StatusOr<RankReplanResult> rr = RankReplan(in, method, stop);
        if (!rr.ok()) {
          if (absl::IsFailedPrecondition(rr.status()) || absl::IsDeadlineExceeded(rr.status()) ||
              absl::IsCancelled(rr.status())) {
            st.greedy_detours.push_back(k);
            continue;
          }
          return rr.status();
        }
        ranks = std::move(rr->ranks);
        is_new = std::move(rr->is_new);
        st.new_ranks = rr->num_new;
        st.rank_lp_integral = rr->relaxation_integral;
      }
      st.rank_replan_ms = MsSince(t0);
      st.kept_ranks = static_cast<int64_t>(ranks.size()) - st.new_ranks;
      st.rank_budget = m_bar;
      out.plan.path = prefix.path;
      for (Waypoint& wp : out.plan.path) wp.rank = -1;  // the tour's tags index the new partition
      out.plan.sweeps = prefix.sweeps;
      auto detail = std::make_shared<OarpDetail>();
      detail->ranks = ranks;
      out.plan.detail = detail;
      out.stats.kept_path_pieces = 0;
      out.stats.kept_path_m = 0;
      const double tour_budget = std::max(1e-3, budget_s - absl::ToDoubleSeconds(absl::Now() - t0));
      ASSIGN_OR_RETURN(bool ok,
                       TourReplan(c, prefix, ranks, is_new, options, stop, tour_budget, &out));
      if (!ok) {
        st.greedy_detours.push_back(k);
        continue;
      }
      if (estimator != nullptr && w.CountFree() > 0 && st.new_ranks > 0) {
        // Trivial replans (nothing to repartition) would teach it nothing.
        estimator->Record(st.new_ranks, absl::ToDoubleSeconds(absl::Now() - t0));
      }
      st.method = ReplanMethodName(options.method == ReplanMethod::kAuto ? ReplanMethod::kAuto
                                                                         : options.method);
      if (options.method == ReplanMethod::kAuto) {
        st.method = method == RankReplanMethod::kIlp1 ? "auto/ilp1" : "auto/ilp2";
      }
      st.replanned_encounter = k;
      st.time_to_encounter_s = tau;
      done = true;
    }
    if (!done) greedy();
  }
  // Statistics of the new plan, from its path.
  PlanStats& s = out.plan.stats;
  s = ComputePathStats(out.plan.path, c.robot);
  s.grid_rows = drive.rows();
  s.grid_cols = drive.cols();
  s.free_cells = st.remaining_cells;
  std::vector<uint8_t> swept(free.size(), 0);
  for (const CoverageSweep& sw : out.plan.sweeps) {
    for (const CellIndex& cell : sw.cells) {
      s.covered_cells += !swept[drive.Index(cell.row, cell.col)];
      swept[drive.Index(cell.row, cell.col)] = 1;
    }
  }
  s.num_ranks = st.new_ranks + st.kept_ranks;
  s.unreachable_free_cells = area->unreachable_cells;
  s.mission_covered_cells = old.plan.stats.mission_covered_cells + st.covered_cells_before;
  s.mission_cut_off_cells = old.plan.stats.mission_cut_off_cells + st.newly_unreachable_cells;
  s.mission_obstructed_cells = old.plan.stats.mission_obstructed_cells + st.newly_obstructed_cells;
  s.map_free_area_m2 = old.plan.stats.map_free_area_m2;
  s.partition_ms = st.rank_replan_ms;
  s.transitions_ms = st.transitions_ms;
  s.tour_ms = st.tour_ms;
  st.total_ms = MsSince(start);
  s.planning_ms = st.total_ms;
  s.partition_solver = st.method;
  s.tour_solver = "gtsp";
  return out;
}

absl::Status ValidateObservations(const Grid& grid, const Observations& observations) {
  return replan_internal::BlockedCells(grid, observations).status();
}

absl::StatusOr<ReplanResult> Resume(const RetainedPlan& old, const RobotProgress& stopped_at,
                                    const Pose2& robot, const Observations& observations,
                                    const ReplanOptions& options, ReplanEstimator* estimator,
                                    double* rejoin_m) {
  const absl::Time start = absl::Now();
  if (!std::isfinite(robot.x) || !std::isfinite(robot.y) || !std::isfinite(robot.theta)) {
    return absl::InvalidArgumentError("pose: x, y and theta must be finite");
  }
  // The remainder from the stop point (its budgets count from there, which
  // only leaves more time: the robot first drives back).
  ASSIGN_OR_RETURN(ReplanResult out, Replan(old, stopped_at, observations, options, estimator));
  if (out.plan.path.empty() || out.area == nullptr || out.area->drive == nullptr) {
    return absl::InternalError("replan returned no path to resume");
  }
  const Grid& drive = *out.area->drive;
  const Waypoint stop = out.plan.path.front();
  // The drive grid is the free area connected to where the robot stopped.
  absl::StatusOr<CellIndex> joined = JoinCell(drive, robot, "pose");
  if (!joined.ok()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "pose: the robot at (%.3f, %.3f) is neither in nor next to a free cell from which it can "
        "drive to "
        "where it stopped (%.3f, %.3f); obstacles reported on the way may cut it off",
        robot.x, robot.y, stop.x, stop.y));
  }
  std::vector<Waypoint> path = {{robot.x, robot.y, robot.theta, SegmentKind::kStart, -1}};
  ASSIGN_OR_RETURN(bool routed,
                   AppendRoute(drive, {robot.x, robot.y}, Pose2{stop.x, stop.y, stop.theta},
                               options.stop, &path));
  if (!routed)
    return absl::DeadlineExceededError("no time left to route the robot back to where it stopped");
  const Point2 reached{path.back().x, path.back().y};
  if (std::hypot(reached.x - stop.x, reached.y - stop.y) > 1e-6) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "pose: the robot at (%.3f, %.3f) cannot reach where it stopped (%.3f, %.3f)", robot.x,
        robot.y, stop.x, stop.y));
  }
  double back = 0.0;
  for (size_t i = 1; i < path.size(); ++i)
    back += std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  if (rejoin_m != nullptr) *rejoin_m = back;
  const int offset = static_cast<int>(path.size()) - 1;
  for (size_t i = 1; i < out.plan.path.size(); ++i) path.push_back(out.plan.path[i]);
  for (CoverageSweep& s : out.plan.sweeps) s.waypoint += offset;
  out.plan.path = std::move(path);
  PlanStats& s = out.plan.stats;
  const PlanStats moved = ComputePathStats(out.plan.path, old.request.common.robot);
  s.num_turns = moved.num_turns;
  s.coverage_length_m = moved.coverage_length_m;
  s.transition_length_m = moved.transition_length_m;
  s.estimated_duration_s = moved.estimated_duration_s;
  s.turning_time_s = moved.turning_time_s;
  out.stats.total_ms = MsSince(start);
  s.planning_ms = out.stats.total_ms;
  return out;
}

}  // namespace covplan
