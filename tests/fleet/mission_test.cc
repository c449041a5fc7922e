// Redividing a fleet mission while the robots drive: a robot that stops for
// good hands what it has left to the others, a robot that joins takes a
// share, and nothing left to cover is lost.
#include <memory>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/fleet/mission.h"
#include "tests/fleet/fleet_fixtures.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;
using testing::Robot;

struct Mission {
  OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  PlannerRegistry registry = BuiltinPlanners();
  LocalArtifactCache cache;
  PlanningEngine engine{&registry, &cache, EngineLimits{}};
  MapSource source = testing::SourceOfMap(map, "office");
  FleetRequest request;
  FleetPlan plan;
  std::vector<std::shared_ptr<const RetainedPlan>> retained;

  Mission() {
    request.base.planner = "oarp";
    request.base.common.robot.tool_width_m = 0.8;
    request.base.common.time_limit_s = 1.0;
    request.robots = {Robot("a", 0.8, 1.5, 1.5), Robot("b", 0.8, 20.0, 1.5),
                      Robot("c", 0.8, 10.0, 10.0)};
    absl::StatusOr<FleetPlan> p = PlanFleet(engine, source, request);
    EXPECT_TRUE(p.ok()) << p.status();
    plan = *std::move(p);
    for (size_t i = 0; i < plan.robots.size(); ++i) {
      auto r = std::make_shared<RetainedPlan>();
      r->plan = plan.robots[i].result.plan;
      r->request = request.RobotRequest(i);
      r->area = plan.robots[i].result.area;
      retained.push_back(r);
    }
  }
  // Robot i a third of the way along its path.
  MissionRobot Driving(size_t i, double share) const {
    MissionRobot m;
    m.robot = request.robots[i];
    m.plan = retained[i];
    const std::vector<Waypoint>& path = retained[i]->plan.path;
    const int w = std::max(1, static_cast<int>(path.size() * share));
    m.progress.waypoint = w;
    m.progress.position = Point2{path[w].x, path[w].y};
    return m;
  }
};

// The cells of `plan`'s sweeps after waypoint `after`.
std::vector<uint8_t> SweptAfter(const CoveragePlan& plan, int after, size_t cells) {
  std::vector<uint8_t> out(cells, 0);
  for (const CoverageSweep& s : plan.sweeps) {
    if (s.waypoint <= after) continue;
    for (const CellIndex& c : s.cells) out[plan.grid->Index(c.row, c.col)] = 1;
  }
  return out;
}

TEST(Mission, AStoppedRobotsRemainderGoesToTheOthers) {
  Mission m;
  std::vector<MissionRobot> robots = {m.Driving(0, 0.3), m.Driving(1, 0.3), m.Driving(2, 0.3)};
  robots[1].active = false;
  absl::StatusOr<MissionRedivision> r =
      RedivideMission(m.engine, m.source, m.request.base, robots, MissionOptions{});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_THAT(r->robot_ids, ::testing::ElementsAre("a", "c"));
  ASSERT_EQ(r->plan.robots.size(), 2u);
  EXPECT_GT(r->handed_over_cells, 0);
  const size_t cells = static_cast<size_t>(m.retained[0]->plan.grid->size());
  std::vector<uint8_t> swept(cells, 0);
  for (size_t i = 0; i < 2; ++i) {
    const FleetRobotPlan& rp = r->plan.robots[i];
    EXPECT_EQ(testing::CheckPlanConformance(rp.result.plan, *rp.result.area,
                                            m.request.robots[i == 0 ? 0 : 2].robot),
              "");
    for (const CoverageSweep& s : rp.result.plan.sweeps)
      for (const CellIndex& c : s.cells) swept[rp.result.plan.grid->Index(c.row, c.col)] = 1;
  }
  // Every cell robot b had still to sweep after where it stopped is in the
  // new plans (the cell it stood in may count as swept).
  const int stopped = robots[1].progress.waypoint;
  const std::vector<uint8_t> left = SweptAfter(m.retained[1]->plan, stopped, cells);
  int64_t lost = 0, handed = 0;
  for (size_t c = 0; c < cells; ++c) {
    handed += left[c];
    lost += left[c] && !swept[c];
  }
  EXPECT_GT(handed, 0);
  EXPECT_LE(lost, 2) << "cells robot b left are missing from the new plans";
  // The survivors start where they stand.
  for (size_t i = 0; i < 2; ++i) {
    const Waypoint& first = r->plan.robots[i].result.plan.path.front();
    const Point2 at = *robots[i == 0 ? 0 : 2].progress.position;
    EXPECT_NEAR(first.x, at.x, 1e-9);
    EXPECT_NEAR(first.y, at.y, 1e-9);
  }
}

TEST(Mission, AJoiningRobotTakesAShare) {
  Mission m;
  std::vector<MissionRobot> robots = {m.Driving(0, 0.1), m.Driving(1, 0.1), m.Driving(2, 0.1)};
  MissionRobot d;
  d.robot = Robot("d", 0.8, 12.0, 1.5);
  d.pose = d.robot.robot.start;
  robots.push_back(d);
  absl::StatusOr<MissionRedivision> r =
      RedivideMission(m.engine, m.source, m.request.base, robots, MissionOptions{});
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_EQ(r->plan.robots.size(), 4u);
  EXPECT_FALSE(r->plan.robots[3].idle);
  EXPECT_GT(r->plan.robots[3].assigned_cells, 0);
  EXPECT_EQ(r->plan.covered_cells, r->remaining_cells);
}

// Robot a meets an obstacle on cells robot c has still to sweep (its plan is
// replanned around it; c's is not); c then stops. The obstacle is closed for
// the robot that takes over c's cells: no new plan sweeps or drives there.
TEST(Mission, AnObstacleOneRobotMetIsClosedForTheOthers) {
  Mission m;
  const size_t cells = static_cast<size_t>(m.retained[0]->plan.grid->size());
  std::vector<MissionRobot> robots = {m.Driving(0, 0.3), m.Driving(1, 0.3), m.Driving(2, 0.3)};
  // Three cells of a rank in the middle of what robot c has left.
  std::vector<const CoverageSweep*> ahead;
  for (const CoverageSweep& s : m.retained[2]->plan.sweeps) {
    if (s.waypoint > robots[2].progress.waypoint && s.cells.size() >= 5) ahead.push_back(&s);
  }
  ASSERT_FALSE(ahead.empty());
  const CoverageSweep& rank = *ahead[ahead.size() / 2];
  Observations seen;
  seen.cells.assign(rank.cells.begin() + 1, rank.cells.begin() + 4);
  ReplanOptions options;
  options.tour_time_limit_s = 0.2;
  absl::StatusOr<ReplanResult> met =
      Replan(*m.retained[0], robots[0].progress, seen, options, /*estimator=*/nullptr);
  ASSERT_TRUE(met.ok()) << met.status();
  auto replanned = std::make_shared<RetainedPlan>(*m.retained[0]);
  replanned->plan = met->plan;
  replanned->area = met->area;
  robots[0].plan = replanned;
  robots[0].progress = RobotProgress{};
  robots[2].active = false;

  absl::StatusOr<MissionRedivision> r =
      RedivideMission(m.engine, m.source, m.request.base, robots, MissionOptions{});
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_EQ(r->plan.robots.size(), 2u);
  EXPECT_GE(r->cut_off_cells, 3);
  std::vector<uint8_t> swept(cells, 0);
  for (size_t i = 0; i < 2; ++i) {
    const FleetRobotPlan& rp = r->plan.robots[i];
    const RobotModel& model = m.request.robots[i == 0 ? 0 : 1].robot;
    EXPECT_EQ(testing::CheckPlanConformance(rp.result.plan, *rp.result.area, model), "");
    EXPECT_EQ(testing::CheckPathStaysFree(*met->area->drive, rp.result.plan.path, true), "")
        << "robot " << rp.id << " drives into the obstacle robot a met";
    for (const CoverageSweep& s : rp.result.plan.sweeps)
      for (const CellIndex& c : s.cells) swept[rp.result.plan.grid->Index(c.row, c.col)] = 1;
  }
  for (const CellIndex& c : seen.cells) {
    EXPECT_FALSE(swept[m.retained[0]->plan.grid->Index(c.row, c.col)])
        << "cell (" << c.row << ", " << c.col << ") of the obstacle is swept";
  }
  // Everything else robot c left is still swept by someone, but for the
  // cells the obstacle closes or cuts off from the robots (which of c's
  // ranks it lands on depends on the anytime tour, and a rank in a doorway
  // cuts a room off): those are closed on the mission's drive grid and
  // counted as cut off.
  const std::vector<uint8_t> left =
      SweptAfter(m.retained[2]->plan, robots[2].progress.waypoint, cells);
  const std::vector<uint8_t>& open = r->plan.robots[0].result.area->drive->free_flags();
  int64_t lost = 0, lost_open = 0;
  for (size_t c = 0; c < cells; ++c) {
    if (!left[c] || swept[c]) continue;
    ++lost;
    lost_open += open[c] != 0;
  }
  EXPECT_LE(lost_open, 2) << "cells robot c left that the robots can reach are missing";
  EXPECT_LE(lost, r->cut_off_cells + 2);
}

TEST(Mission, NoActiveRobotWhileCellsAreLeftIsRefused) {
  Mission m;
  std::vector<MissionRobot> robots = {m.Driving(0, 0.2)};
  robots[0].active = false;
  absl::StatusOr<MissionRedivision> r =
      RedivideMission(m.engine, m.source, m.request.base, robots, MissionOptions{});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("no robot is active"));
  MissionRobot lost;
  lost.robot = Robot("e", 0.8, 1.0, 1.0);
  robots = {m.Driving(0, 0.2), lost};
  r = RedivideMission(m.engine, m.source, m.request.base, robots, MissionOptions{});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("robots[1] ('e'): pose"));
}

}  // namespace
}  // namespace covplan
