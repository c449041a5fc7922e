// OARP-Replan end to end on the shipped office: the robot drives the plan of
// the plain map and meets the furnished map's extra obstacles. Every method
// passes the conformance suite on the remainder (every remaining reachable
// cell swept, nothing through a known or new obstacle), plans start at the
// robot and end where the old plan ended; bad progress and bad obstacles are
// InvalidArgument; an expired deadline still gets the greedy detour.
#include "planner/replan/replanner.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/map_io.h"
#include "tests/testing/oarp_options.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

OccupancyMap Load(const std::string& name) { return testing::LoadShippedMap(name); }

struct Mission {
  RetainedPlan plan;
  Observations furniture;  // the furnished map's extra obstacles, as cells
};

// Plans the plain office; the new obstacles are the cells that are free on
// the plain grid but blocked on the furnished one.
Mission Office(double tool = 0.8) {
  const OccupancyMap known = Load("sample_office.yaml");
  const OccupancyMap truth = Load("sample_office_furnished.yaml");
  PlanOptions o;
  o.robot.tool_width_m = tool;
  o.time_limit_s = 0.5;
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(known, o);
  EXPECT_TRUE(r.ok()) << r.status();
  Mission m;
  m.plan.plan_id = "p-test";
  m.plan.map_id = "office";
  m.plan.plan = r->plan;
  m.plan.area = r->area;
  m.plan.request = o.ToRequest();
  GridOptions go;
  go.cell_size = tool;
  absl::StatusOr<Grid> true_grid = BuildGrid(truth, go);
  EXPECT_TRUE(true_grid.ok());
  const Grid& drive = *r->area->drive;
  for (int64_t i = 0; i < drive.size(); ++i) {
    const CellIndex c = drive.FromIndex(i);
    if (drive.IsFree(c) && !true_grid->IsFree(c)) m.furniture.cells.push_back(c);
  }
  EXPECT_GT(m.furniture.cells.size(), 5u);
  return m;
}

RobotProgress Early(const CoveragePlan& plan) {
  RobotProgress p;
  p.waypoint = static_cast<int>(plan.path.size()) / 6;
  const Waypoint& a = plan.path[p.waypoint - 1];
  const Waypoint& b = plan.path[p.waypoint];
  p.position = Point2{(a.x + b.x) / 2, (a.y + b.y) / 2};
  return p;
}

// A plan of `map` at a 1 m tool with the greedy tour, kept as a server keeps it.
absl::StatusOr<RetainedPlan> GreedyPlanWithMetreTool(const OccupancyMap& map) {
  PlanOptions o;
  o.robot.tool_width_m = 1.0;
  o.options = testing::OarpOptionsWith(TourSolver::kGreedy);
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
  if (!r.ok()) return r.status();
  RetainedPlan old;
  old.plan = std::move(r->plan);
  old.area = std::move(r->area);
  old.request = o.ToRequest();
  return old;
}

void ExpectGoodReplan(const ReplanResult& r, const RetainedPlan& old, const RobotProgress& at,
                      const Observations& seen) {
  EXPECT_EQ(testing::CheckPlanConformance(r.plan, *r.area, old.request.common.robot), "");
  // Starts at the robot, ends where the old plan ended.
  ASSERT_GE(r.plan.path.size(), 2u);
  if (at.position) {
    EXPECT_NEAR(r.plan.path.front().x, at.position->x, 0.81);
    EXPECT_NEAR(r.plan.path.front().y, at.position->y, 0.81);
  }
  EXPECT_NEAR(r.plan.path.back().x, old.plan.path.back().x, 1e-9);
  EXPECT_NEAR(r.plan.path.back().y, old.plan.path.back().y, 1e-9);
  // No new obstacle is entered (the drive grid has them blocked; check the cells directly too).
  for (const CellIndex& c : seen.cells) EXPECT_FALSE(r.area->drive->IsFree(c));
  // A robot standing in a cell reported blocked first leaves it (see
  // TheRobotsOwnCellReportedBlockedIsLeftAndNeverEnteredAgain).
  EXPECT_EQ(testing::CheckPathStaysFree(*r.area->drive, r.plan.path, r.stats.robot_cell_blocked),
            "");
  // Honest accounting: swept + remaining + unreachable add up.
  EXPECT_EQ(r.plan.stats.covered_cells, r.stats.remaining_cells);
  EXPECT_EQ(static_cast<int64_t>(r.unreachable.size()), r.stats.newly_unreachable_cells);
}

class EveryMethod : public ::testing::TestWithParam<ReplanMethod> {};

TEST_P(EveryMethod, FurnitureOfTheFurnishedOfficeIsReplannedAroundAndEverythingLeftIsSwept) {
  const Mission m = Office();
  const RobotProgress at = Early(m.plan.plan);
  ReplanEstimator estimator;
  ReplanOptions options;
  options.method = GetParam();
  absl::StatusOr<ReplanResult> r = Replan(m.plan, at, m.furniture, options, &estimator);
  ASSERT_TRUE(r.ok()) << r.status();
  std::printf(
      "method %s: encounters %d, detours %zu, replanned at %d (tau %.1f s), budget %lld, "
      "new %lld, kept %lld, pieces %lld; rank %.1f ms, transitions %.1f ms, tour %.1f ms, "
      "total %.1f ms\n",
      r->stats.method.c_str(), r->stats.num_encounters, r->stats.greedy_detours.size(),
      r->stats.replanned_encounter, r->stats.time_to_encounter_s,
      static_cast<long long>(r->stats.rank_budget), static_cast<long long>(r->stats.new_ranks),
      static_cast<long long>(r->stats.kept_ranks),
      static_cast<long long>(r->stats.kept_path_pieces), r->stats.rank_replan_ms,
      r->stats.transitions_ms, r->stats.tour_ms, r->stats.total_ms);
  ExpectGoodReplan(*r, m.plan, at, m.furniture);
  EXPECT_GT(r->stats.num_encounters, 0);
  EXPECT_GT(r->stats.newly_blocked_cells, 0);
  if (GetParam() == ReplanMethod::kGreedyDetour) {
    EXPECT_EQ(static_cast<int>(r->stats.greedy_detours.size()), r->stats.num_encounters);
  }
  if (GetParam() == ReplanMethod::kIlp1 || GetParam() == ReplanMethod::kIlp2 ||
      GetParam() == ReplanMethod::kAuto) {
    // The robot is far from the first obstacle: Algorithm 1 replans at it.
    EXPECT_GE(r->stats.replanned_encounter, 0) << r->stats.method;
    EXPECT_GT(r->stats.kept_ranks, 0);
    EXPECT_LE(r->stats.new_ranks, std::max<int64_t>(r->stats.rank_budget, 0));
    EXPECT_LT(r->stats.total_ms, 1000 * r->stats.time_to_encounter_s);
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, EveryMethod,
                         ::testing::Values(ReplanMethod::kGreedyDetour, ReplanMethod::kIlp1,
                                           ReplanMethod::kIlp2, ReplanMethod::kAuto,
                                           ReplanMethod::kFull),
                         [](const ::testing::TestParamInfo<ReplanMethod>& info) {
                           return std::string(ReplanMethodName(info.param));
                         });

TEST(Replan, AReplannedPlanCanBeReplannedAgain) {
  const Mission m = Office();
  RobotProgress at = Early(m.plan.plan);
  ReplanEstimator estimator;
  Observations first, second;
  first.cells.assign(m.furniture.cells.begin(),
                     m.furniture.cells.begin() + m.furniture.cells.size() / 2);
  second.cells.assign(m.furniture.cells.begin() + m.furniture.cells.size() / 2,
                      m.furniture.cells.end());
  absl::StatusOr<ReplanResult> r1 = Replan(m.plan, at, first, ReplanOptions(), &estimator);
  ASSERT_TRUE(r1.ok()) << r1.status();
  RetainedPlan next = m.plan;
  next.plan = r1->plan;
  next.area = r1->area;
  RobotProgress later;
  later.waypoint = static_cast<int>(next.plan.path.size()) / 4;
  const Waypoint& a = next.plan.path[later.waypoint - 1];
  later.position = Point2{a.x, a.y};
  absl::StatusOr<ReplanResult> r2 = Replan(next, later, second, ReplanOptions(), &estimator);
  ASSERT_TRUE(r2.ok()) << r2.status();
  ExpectGoodReplan(*r2, next, later, second);
}

TEST(Replan, ObstaclesBehindTheRobotChangeNothing) {
  const Mission m = Office();
  RobotProgress at;
  at.waypoint = static_cast<int>(m.plan.plan.path.size()) - 2;  // near the end
  const Waypoint& w = m.plan.plan.path[at.waypoint - 1];
  at.position = Point2{w.x, w.y};
  // A cell swept early in the plan, well away from what is left to drive.
  const Grid& g = *m.plan.area->drive;
  Observations seen;
  for (const CoverageSweep& s : m.plan.plan.sweeps) {
    if (!seen.cells.empty() || s.waypoint > static_cast<int>(m.plan.plan.path.size()) / 3) break;
    for (const CellIndex& c : s.cells) {
      const Point2 p = g.CellCenter(c);
      double nearest = 1e9;
      for (size_t i = at.waypoint - 1; i + 1 < m.plan.plan.path.size(); ++i) {
        const Waypoint& a = m.plan.plan.path[i];
        const Waypoint& b = m.plan.plan.path[i + 1];
        for (int k = 0; k <= 50; ++k) {
          const double t = k / 50.0;
          nearest = std::min(nearest,
                             std::hypot(a.x + t * (b.x - a.x) - p.x, a.y + t * (b.y - a.y) - p.y));
        }
      }
      if (nearest > 2 * g.cell_size()) {
        seen.cells = {c};
        break;
      }
    }
  }
  ASSERT_EQ(seen.cells.size(), 1u);
  absl::StatusOr<ReplanResult> r = Replan(m.plan, at, seen, ReplanOptions(), nullptr);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->stats.num_encounters, 0);
  EXPECT_EQ(r->stats.method, "unchanged");
  ExpectGoodReplan(*r, m.plan, at, seen);
}

TEST(Replan, AnExpiredDeadlineStillGetsTheGreedyDetour) {
  const Mission m = Office();
  const RobotProgress at = Early(m.plan.plan);
  ReplanOptions options;
  options.stop = StopToken::WithDeadline(absl::Now() - absl::Seconds(1));
  ReplanEstimator estimator;
  absl::StatusOr<ReplanResult> r = Replan(m.plan, at, m.furniture, options, &estimator);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->stats.method, "greedy_detour");
  ExpectGoodReplan(*r, m.plan, at, m.furniture);
}

// Encounters whose time-to-reach is too short for a replan are driven around
// (greedy detour); Algorithm 1 replans at the first one with enough time.
TEST(Replan, EncountersWithTooLittleTimeAreDetouredAndALaterOneReplanned) {
  const Mission m = Office();
  const RobotProgress at = Early(m.plan.plan);
  ReplanEstimator estimator;
  ReplanOptions options;
  ReplanOptions probe;
  probe.method = ReplanMethod::kGreedyDetour;
  absl::StatusOr<ReplanResult> all = Replan(m.plan, at, m.furniture, probe, &estimator);
  ASSERT_TRUE(all.ok());
  ASSERT_GE(all->stats.num_encounters, 3);
  // Keep back more than the first encounter's time-to-reach but less than a later one's.
  absl::StatusOr<ReplanResult> first = Replan(m.plan, at, m.furniture, ReplanOptions(), &estimator);
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->stats.replanned_encounter, 0);
  options.safety_margin_s = first->stats.time_to_encounter_s + 0.5;
  absl::StatusOr<ReplanResult> r = Replan(m.plan, at, m.furniture, options, &estimator);
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectGoodReplan(*r, m.plan, at, m.furniture);
  ASSERT_FALSE(r->stats.greedy_detours.empty());
  EXPECT_EQ(r->stats.greedy_detours.front(), 0);
  EXPECT_GT(r->stats.replanned_encounter, 0);
  EXPECT_GT(r->stats.time_to_encounter_s, options.safety_margin_s);
}

// The old end (where the robot returns, e.g. its dock) is blocked by a new
// obstacle: every method still answers; the plan ends at the nearest
// reachable cell and says so.
TEST(Replan, ABlockedEndMovesTheEndInsteadOfFailing) {
  const Mission m = Office();
  const RobotProgress at = Early(m.plan.plan);
  const Waypoint& end = m.plan.plan.path.back();
  Observations seen;
  seen.points = {{end.x, end.y}};
  for (ReplanMethod method :
       {ReplanMethod::kAuto, ReplanMethod::kGreedyDetour, ReplanMethod::kFull}) {
    ReplanOptions options;
    options.method = method;
    absl::StatusOr<ReplanResult> r = Replan(m.plan, at, seen, options, nullptr);
    ASSERT_TRUE(r.ok()) << ReplanMethodName(method) << ": " << r.status();
    EXPECT_TRUE(r->stats.end_moved);
    EXPECT_EQ(testing::CheckPlanConformance(r->plan, *r->area, m.plan.request.common.robot), "")
        << ReplanMethodName(method);
    const Waypoint& last = r->plan.path.back();
    EXPECT_LT(std::hypot(last.x - end.x, last.y - end.y), 1.2) << ReplanMethodName(method);
    EXPECT_TRUE(r->area->drive->IsFree(r->area->drive->CellAt({last.x, last.y})));
  }
}

TEST(Replan, MalformedProgressAndObstaclesAreInvalidArgument) {
  const Mission m = Office();
  const int n = static_cast<int>(m.plan.plan.path.size());
  struct Case {
    RobotProgress at;
    Observations seen;
    const char* message;
  };
  RobotProgress past;
  past.waypoint = n;
  past.position = Point2{0, 0};
  RobotProgress nan_pos = Early(m.plan.plan);
  nan_pos.position = Point2{std::nan(""), 1.0};
  RobotProgress far = Early(m.plan.plan);
  far.position->x += 5.0;
  RobotProgress beyond;
  beyond.distance_m = 1e6;
  RobotProgress negative;
  negative.distance_m = -1;
  RobotProgress nothing;
  Observations off_grid;
  off_grid.cells = {{-1, 3}};
  Observations nan_point;
  nan_point.points = {{1.0, std::nan("")}};
  Observations bad_polygon;
  bad_polygon.polygons = {{{{1, 1}, {3, 1}, {1, 3}, {3, 3}, {1, 1}}, {}}};
  const std::vector<Case> cases = {
      {past, {}, "progress.waypoint"},
      {nan_pos, {}, "progress.position"},
      {far, {}, "from segment"},
      {beyond, {}, "past the end"},
      {negative, {}, "progress.distance_m"},
      {nothing, {}, "progress:"},
      {Early(m.plan.plan), off_grid, "obstacles.cells[0]"},
      {Early(m.plan.plan), nan_point, "obstacles.points[0]"},
      {Early(m.plan.plan), bad_polygon, "obstacles.polygons[0].outer"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    absl::StatusOr<ReplanResult> r =
        Replan(m.plan, cases[i].at, cases[i].seen, ReplanOptions(), nullptr);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << i << ": " << r.status();
    EXPECT_THAT(std::string(r.status().message()), HasSubstr(cases[i].message)) << i;
  }
}

// A new obstacle that an old any-angle transition only clips (or meets at a
// grid corner) is an encounter too: the replanned path must not cut into it.
TEST(Replan, ACellThatAnOldSegmentOnlyClipsIsAvoided) {
  OccupancyMap open(240, 240, 0.05, {0.0, 0.0});  // 12 m x 12 m, all free
  for (int r = 0; r < 240; ++r) {
    for (int c = 0; c < 240; ++c) open.set(r, c, CellState::kFree);
  }
  absl::StatusOr<RetainedPlan> planned = GreedyPlanWithMetreTool(open);
  ASSERT_TRUE(planned.ok()) << planned.status();
  RetainedPlan old = *std::move(planned);
  // Replace the path by one long diagonal transition and its return.
  old.plan.path = {{0.5, 0.5, 0, SegmentKind::kStart, -1},
                   {10.5, 7.5, std::atan2(7.0, 10.0), SegmentKind::kTransition, -1},
                   {0.5, 0.5, std::atan2(-7.0, -10.0), SegmentKind::kTransition, -1}};
  old.plan.sweeps.clear();
  // Cells the diagonal clips without any 1/8-cell sample landing in them.
  for (const CellIndex& cell : {CellIndex{2, 4}, CellIndex{4, 6}, CellIndex{6, 9}}) {
    RobotProgress at;
    at.distance_m = 0.0;
    Observations seen;
    seen.cells = {cell};
    for (ReplanMethod method : {ReplanMethod::kGreedyDetour, ReplanMethod::kAuto}) {
      ReplanOptions options;
      options.method = method;
      absl::StatusOr<ReplanResult> res = Replan(old, at, seen, options, nullptr);
      ASSERT_TRUE(res.ok()) << res.status();
      EXPECT_EQ(testing::CheckPathStaysFree(*res->area->drive, res->plan.path), "")
          << cell.row << "," << cell.col << " " << ReplanMethodName(method);
    }
  }
}

// Resume: from a dock back to where the robot stopped, around furniture it
// found since, then on over the rest; the whole plan passes the conformance
// checks, and the mission's account adds up.
TEST(Resume, DrivesBackToTheStopPointAndCoversTheRest) {
  Mission m = Office();
  const RobotProgress stopped = Early(m.plan.plan);
  const Waypoint& start = m.plan.plan.path.front();
  const Pose2 dock{start.x, start.y, 0.3};
  ReplanOptions o;
  o.stop = StopToken::WithTimeout(absl::Seconds(30));
  ReplanEstimator estimator;
  double rejoin_m = -1.0;
  absl::StatusOr<ReplanResult> r =
      Resume(m.plan, stopped, dock, m.furniture, o, &estimator, &rejoin_m);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(testing::CheckPlanConformance(r->plan, *r->area, m.plan.request.common.robot), "");
  EXPECT_EQ(testing::CheckPathStaysFree(*r->area->drive, r->plan.path), "");
  EXPECT_NEAR(r->plan.path.front().x, dock.x, 1e-12);
  EXPECT_NEAR(r->plan.path.front().y, dock.y, 1e-12);
  EXPECT_GT(rejoin_m, 0.0);
  // The drive back ends where the robot stopped: some waypoint is there.
  bool passes_stop = false;
  for (const Waypoint& w : r->plan.path) {
    passes_stop |= std::hypot(w.x - stopped.position->x, w.y - stopped.position->y) < 1e-9;
  }
  EXPECT_TRUE(passes_stop);
  EXPECT_EQ(r->plan.stats.covered_cells, r->stats.remaining_cells);
  EXPECT_EQ(r->plan.stats.mission_covered_cells + r->stats.remaining_cells +
                r->plan.stats.mission_cut_off_cells + r->plan.stats.mission_obstructed_cells,
            m.plan.plan.stats.free_cells);
  // A pose off the grid names the pose.
  absl::StatusOr<ReplanResult> off = Resume(m.plan, stopped, Pose2{-50, -50, 0}, {}, o, &estimator);
  EXPECT_EQ(off.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(off.status().message()), ::testing::HasSubstr("pose"));
}

// Two 6 m x 6 m rooms joined by a one-cell door. The door reported blocked
// cuts the room the robot did not stop in off: a Resume from there is
// refused, and the message says why.
TEST(Resume, APoseCutOffFromWhereTheRobotStoppedIsRefused) {
  OccupancyMap rooms(260, 120, 0.05, {0.0, 0.0});  // 13 m wide, 6 m high
  for (int r = 0; r < 120; ++r) {
    for (int c = 0; c < 260; ++c) {
      const bool wall = c >= 120 && c < 140 && !(r >= 40 && r < 60);  // x in [6, 7) m, a 1 m door
      rooms.set(r, c, wall ? CellState::kOccupied : CellState::kFree);
    }
  }
  absl::StatusOr<RetainedPlan> planned = GreedyPlanWithMetreTool(rooms);
  ASSERT_TRUE(planned.ok()) << planned.status();
  const RetainedPlan old = *std::move(planned);
  const Grid& drive = *old.area->drive;
  // The door: the one free cell of the wall's grid column.
  std::vector<CellIndex> door;
  for (int r = 0; r < drive.rows(); ++r) {
    if (drive.IsFree(r, 6)) door.push_back({r, 6});
  }
  std::string picture;
  for (int r = 0; r < drive.rows(); ++r) {
    for (int c = 0; c < drive.cols(); ++c) picture += drive.IsFree(r, c) ? '.' : '#';
    picture += '\n';
  }
  ASSERT_EQ(door.size(), 1u) << picture;
  // Stopped inside a room, not in the doorway.
  RobotProgress stopped;
  for (int w = static_cast<int>(old.plan.path.size()) / 6;
       w < static_cast<int>(old.plan.path.size()); ++w) {
    const Waypoint& a = old.plan.path[w - 1];
    const Waypoint& b = old.plan.path[w];
    const Point2 mid{(a.x + b.x) / 2, (a.y + b.y) / 2};
    if (mid.x < 5.5 || mid.x > 7.5) {
      stopped.waypoint = w;
      stopped.position = mid;
      break;
    }
  }
  ASSERT_TRUE(stopped.position.has_value());
  const bool left = stopped.position->x < 6.0;
  const Pose2 same_room{left ? 2.5 : 10.5, 3.0, 0.0};
  const Pose2 other_room{left ? 10.5 : 2.5, 3.0, 0.0};
  Observations door_blocked;
  door_blocked.cells = door;
  ReplanOptions options;
  options.stop = StopToken::WithTimeout(absl::Seconds(30));
  absl::StatusOr<ReplanResult> cut_off =
      Resume(old, stopped, other_room, door_blocked, options, nullptr);
  EXPECT_EQ(cut_off.status().code(), absl::StatusCode::kInvalidArgument) << cut_off.status();
  EXPECT_THAT(std::string(cut_off.status().message()), HasSubstr("can drive to where it stopped"));
  // The same door open, or a pose in the robot's room: resumed.
  absl::StatusOr<ReplanResult> open = Resume(old, stopped, other_room, {}, options, nullptr);
  ASSERT_TRUE(open.ok()) << open.status();
  absl::StatusOr<ReplanResult> same =
      Resume(old, stopped, same_room, door_blocked, options, nullptr);
  ASSERT_TRUE(same.ok()) << same.status();
  EXPECT_EQ(testing::CheckPathStaysFree(*same->area->drive, same->plan.path), "");
}

TEST(Estimator, LearnsFromSolvesAndPersists) {
  ReplanEstimator e;
  const int64_t prior = e.Budget(0.5);
  EXPECT_GT(prior, 0);
  EXPECT_EQ(e.Budget(0.0), -1);
  EXPECT_LE(e.Budget(0.1), e.Budget(1.0));  // monotone
  // Slow solves: 20 ms + 10 ms per new rank.
  for (int m = 0; m < 40; ++m) e.Record(m, 0.02 + 0.01 * m);
  const int64_t learned = e.Budget(0.555);
  EXPECT_NEAR(static_cast<double>(learned), 53.0, 3.0);
  EXPECT_LT(learned, prior);
  EXPECT_NEAR(e.Predict(10), 0.12, 0.02);
  ReplanEstimator restored;
  ASSERT_TRUE(restored.Parse(e.Serialize()).ok());
  EXPECT_EQ(restored.Budget(0.555), learned);
  EXPECT_EQ(restored.num_samples(), 40);
  EXPECT_FALSE(restored.Parse("garbage\n1 2\n").ok());
  // Samples that all share one rank count cannot fix a slope: the prior's is kept.
  ReplanEstimator flat;
  for (int k = 0; k < 8; ++k) flat.Record(0, 0.2);
  EXPECT_LT(flat.Budget(0.21), 10);
  EXPECT_GE(flat.Predict(0), 0.2 - 1e-9);
  EXPECT_FALSE(restored.Parse("covplan.replan_estimator.v1\n-1 2\n").ok());
}

// The robot reports its own cell blocked (it stands where an obstacle now
// is, e.g. clutter around a parked robot). The cell stays blocked: the plan
// leaves it with its first move and never comes back to it, so a later replan
// that is told nothing new cannot route through it either.
TEST(Replan, TheRobotsOwnCellReportedBlockedIsLeftAndNeverEnteredAgain) {
  const Mission m = Office();
  const Grid& old_drive = *m.plan.area->drive;
  // The robot halfway along a coverage segment early in the plan (those run
  // through free cells); `inside` is a hair behind it: the cell it stands in.
  const std::vector<Waypoint>& old_path = m.plan.plan.path;
  RobotProgress at;
  Point2 inside;
  for (size_t k = old_path.size() / 6; k < old_path.size() && !at.position; ++k) {
    const Waypoint& a = old_path[k - 1];
    const Waypoint& b = old_path[k];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    if (b.kind != SegmentKind::kCoverage || len < 2 * old_drive.cell_size()) continue;
    const Point2 mid{(a.x + b.x) / 2, (a.y + b.y) / 2};
    inside = Point2{mid.x - 1e-4 * (b.x - a.x) / len, mid.y - 1e-4 * (b.y - a.y) / len};
    if (!old_drive.IsFree(old_drive.CellAt(inside))) continue;
    at.waypoint = static_cast<int>(k);
    at.position = mid;
  }
  ASSERT_TRUE(at.position.has_value());
  const CellIndex robot_cell = old_drive.CellAt(inside);
  Observations seen;
  seen.points = {inside};
  for (ReplanMethod method : {ReplanMethod::kGreedyDetour, ReplanMethod::kIlp1, ReplanMethod::kIlp2,
                              ReplanMethod::kAuto, ReplanMethod::kFull}) {
    SCOPED_TRACE(ReplanMethodName(method));
    ReplanOptions options;
    options.method = method;
    absl::StatusOr<ReplanResult> r = Replan(m.plan, at, seen, options, nullptr);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_TRUE(r->stats.robot_cell_blocked);
    EXPECT_FALSE(r->stats.robot_cell_kept_free);
    EXPECT_EQ(r->stats.newly_blocked_cells, 1);
    const Grid& drive = *r->area->drive;
    EXPECT_FALSE(drive.IsFree(robot_cell));
    EXPECT_EQ(r->plan.stats.covered_cells, r->stats.remaining_cells);
    // Sample the path: it may start in the robot's cell; once out, every
    // point lies in a free cell of the new drive grid.
    bool left = false;
    const std::vector<Waypoint>& path = r->plan.path;
    for (size_t i = 1; i < path.size(); ++i) {
      const Waypoint& p = path[i - 1];
      const Waypoint& q = path[i];
      const int steps =
          std::max(1, static_cast<int>(std::ceil(std::hypot(q.x - p.x, q.y - p.y) / 0.01)));
      for (int k = 0; k <= steps; ++k) {
        const double t = static_cast<double>(k) / steps;
        const CellIndex c = drive.CellAt({p.x + t * (q.x - p.x), p.y + t * (q.y - p.y)});
        if (!left && c == robot_cell) continue;
        left = true;
        ASSERT_TRUE(drive.IsFree(c))
            << "segment " << i << " enters (" << c.row << ", " << c.col << ")";
      }
    }
    EXPECT_TRUE(left);
    // Replanned again, with nothing new: still around the cell.
    RetainedPlan next = m.plan;
    next.plan = r->plan;
    next.area = r->area;
    RobotProgress later;
    later.waypoint = static_cast<int>(next.plan.path.size()) / 2;
    later.position =
        Point2{next.plan.path[later.waypoint - 1].x, next.plan.path[later.waypoint - 1].y};
    Observations other;
    other.cells = {m.furniture.cells.back()};
    absl::StatusOr<ReplanResult> r2 = Replan(next, later, other, options, nullptr);
    ASSERT_TRUE(r2.ok()) << r2.status();
    EXPECT_FALSE(r2->area->drive->IsFree(robot_cell));
    EXPECT_EQ(testing::CheckPathStaysFree(*r2->area->drive, r2->plan.path), "");
  }
}

}  // namespace
}  // namespace covplan
