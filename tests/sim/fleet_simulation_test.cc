// The fleet simulator on the shipped office: three robots plan the plain
// office and drive the furnished one. Without a failure and with one robot
// failing at a third of the plan's makespan, every cell of the true map a
// single simulated robot sweeps is swept by the fleet (no reachable cell is
// left), the failed robot sweeps nothing after its failure, and the
// survivors' redivision covers every cell left at that moment.
#include "planner/sim/fleet_simulator.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/grid/grid.h"
#include "planner/sim/clutter.h"
#include "planner/tour/grid_paths.h"
#include "tests/sim/sim_checks.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using testing::FirstBlockedPoint;
using testing::TrueGrid;

FleetRobot Robot(const std::string& id, double x, double y) {
  FleetRobot r;
  r.id = id;
  r.robot.tool_width_m = 0.8;
  r.robot.start = Pose2{x, y, 0.0};
  r.robot.end = r.robot.start;
  return r;
}

FleetSimulationOptions OfficeFleet() {
  FleetSimulationOptions o;
  o.fleet.base.planner = "oarp";
  o.fleet.base.common.time_limit_s = 0.5;
  o.fleet.robots = {Robot("a", 1.5, 1.5), Robot("b", 20.0, 1.5), Robot("c", 10.0, 10.0)};
  return o;
}

void Print(const FleetSimulationResult& r) {
  std::printf(
      "makespan %.1f s (planned %.1f s), swept %lld of %lld mission cells, %lld of %lld "
      "reachable unswept, in obstacles %.2f m\n",
      r.makespan_s, r.initial.makespan_s, static_cast<long long>(r.swept_cells),
      static_cast<long long>(r.mission_cells), static_cast<long long>(r.unswept_reachable_cells),
      static_cast<long long>(r.reachable_cells), r.length_in_obstacles_m);
  for (const FleetRobotRun& run : r.robots) {
    std::printf("  %s: %zu legs, %lld cells, finish %.1f s, %d replans%s\n", run.id.c_str(),
                run.legs.size(), static_cast<long long>(run.swept_cells), run.finish_s,
                run.num_replans, run.failed ? " (failed)" : "");
  }
  for (const FleetRedivision& d : r.redivisions) {
    std::printf("  redivision at %.1f s: %lld cells left, planned %.1f s, achieved %.1f s\n",
                d.time_s, static_cast<long long>(d.left_cells), d.plan.makespan_s, d.achieved_s);
  }
  for (const std::string& p : r.problems) std::printf("  problem: %s\n", p.c_str());
}

// The cells the robots of `r` reported blocked (for an obstacle smaller than
// the cell, or one that blocks it) on legs that ended by `until_s`, per
// cell of `grid`.
std::vector<uint8_t> Reported(const FleetSimulationResult& r, const Grid& grid,
                              double until_s = std::numeric_limits<double>::infinity()) {
  std::vector<uint8_t> out(static_cast<size_t>(grid.size()), 0);
  for (const FleetRobotRun& run : r.robots) {
    for (const FleetLeg& leg : run.legs) {
      if (leg.end_s > until_s + 1e-9) continue;
      for (const CellIndex& c : leg.run.obstacles_found) out[grid.Index(c.row, c.col)] = 1;
    }
  }
  return out;
}

// Per cell: free on the true grid, not in `closed` (when given), and
// connected to one of the fleet's starts over such cells through the known
// map's walls (the robots' cell model).
std::vector<uint8_t> Reachable(const Grid& known, const Grid& truth,
                               const FleetSimulationOptions& o,
                               const std::vector<uint8_t>* closed = nullptr) {
  std::vector<uint8_t> free(known.free_flags().begin(), known.free_flags().end());
  for (size_t i = 0; i < free.size(); ++i) {
    free[i] = free[i] && truth.free_flags()[i] && (closed == nullptr || !(*closed)[i]);
  }
  const Grid grid = known.WithFreeFlags(std::move(free));
  int32_t num = 0;
  const std::vector<int32_t> comp = FreeComponents(grid, &num);
  std::vector<uint8_t> keep(static_cast<size_t>(num), 0), reachable(comp.size(), 0);
  for (const FleetRobot& r : o.fleet.robots) {
    const CellIndex c = grid.CellAt({r.robot.start->x, r.robot.start->y});
    if (comp[grid.Index(c.row, c.col)] >= 0) keep[comp[grid.Index(c.row, c.col)]] = 1;
  }
  for (size_t i = 0; i < comp.size(); ++i) reachable[i] = comp[i] >= 0 && keep[comp[i]];
  return reachable;
}

// What every fleet run must show: no driving into furniture, every cell a
// single simulated robot sweeps swept by the fleet (but for those a fleet
// robot found a small obstacle in, and what that cut off: `reachable`, the
// fleet's cell model at the end), and about as much of the floor the tool
// can reach (the paths differ within the cells).
void CheckRun(const FleetSimulationResult& r, const SimulationResult& single,
              const std::vector<uint8_t>& reachable) {
  const std::vector<uint8_t>& single_swept = single.swept;
  std::printf("floor: fleet %.4f of %.1f m2, one robot %.4f of %.1f m2\n",
              r.floor.swept_reachable_ratio, r.floor.reachable_area_m2,
              single.floor.swept_reachable_ratio, single.floor.reachable_area_m2);
  EXPECT_GE(r.floor.reachable_area_m2, single.floor.reachable_area_m2 - 1e-9);
  EXPECT_GE(r.floor.swept_reachable_ratio, single.floor.swept_reachable_ratio - 0.01);
  EXPECT_LE(r.floor.swept_reachable_ratio, 1.0);
  const Grid true_grid = TrueGrid(testing::LoadShippedMap("sample_office_furnished.yaml"));
  EXPECT_TRUE(r.completed);
  EXPECT_THAT(r.problems, ::testing::IsEmpty());
  EXPECT_EQ(r.unswept_reachable_cells, 0);
  EXPECT_GT(r.reachable_cells, r.mission_cells / 2);
  int64_t missed = 0;
  for (size_t i = 0; i < single_swept.size(); ++i) {
    missed += single_swept[i] && reachable[i] && !r.swept[i];
  }
  EXPECT_EQ(missed, 0) << "cells the single robot sweeps and the fleet does not";
  double makespan = 0.0, length = 0.0;
  for (const FleetRobotRun& run : r.robots) {
    for (const FleetLeg& leg : run.legs) length += leg.run.path_length_m;
    EXPECT_EQ(FirstBlockedPoint(true_grid, run.driven), "") << run.id;
    makespan = std::max(makespan, run.finish_s);
    for (size_t k = 1; k < run.legs.size(); ++k)
      EXPECT_GE(run.legs[k].start_s, run.legs[k - 1].end_s - 1e-9) << run.id;
  }
  EXPECT_DOUBLE_EQ(r.makespan_s, makespan);
  // Through obstacles smaller than half a cell only, as a single robot (simulator_test).
  EXPECT_LT(r.length_in_obstacles_m, 0.01 * length);
}

TEST(FleetSimulation, ThreeRobotsOneFailingAtAThirdOfTheMakespanLeaveNoReachableCell) {
  const OccupancyMap known = testing::LoadShippedMap("sample_office.yaml");
  const OccupancyMap truth = testing::LoadShippedMap("sample_office_furnished.yaml");
  // What one simulated robot sweeps of the true map.
  SimulationOptions single;
  single.plan.robot.tool_width_m = 0.8;
  single.plan.robot.start = Pose2{1.5, 1.5, 0.0};
  single.plan.time_limit_s = 0.5;
  absl::StatusOr<SimulationResult> one = Simulate(known, truth, single);
  ASSERT_TRUE(one.ok()) << one.status();

  FleetSimulationOptions o = OfficeFleet();
  absl::StatusOr<FleetSimulationResult> all = SimulateFleet(known, truth, o);
  ASSERT_TRUE(all.ok()) << all.status();
  Print(*all);
  const Grid known_grid = TrueGrid(known), true_grid = TrueGrid(truth);
  std::vector<uint8_t> closed = Reported(*all, true_grid);
  CheckRun(*all, *one, Reachable(known_grid, true_grid, o, &closed));
  EXPECT_TRUE(all->redivisions.empty());

  const double t_f = all->initial.makespan_s / 3.0;
  o.failures = {{"b", t_f}};
  absl::StatusOr<FleetSimulationResult> r = SimulateFleet(known, truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  Print(*r);
  closed = Reported(*r, true_grid);
  CheckRun(*r, *one, Reachable(known_grid, true_grid, o, &closed));
  ASSERT_EQ(r->redivisions.size(), 1u);
  const FleetRedivision& d = r->redivisions[0];
  EXPECT_EQ(d.failed_robot, "b");
  EXPECT_THAT(d.robots, ::testing::ElementsAre("a", "c"));
  ASSERT_GT(d.left_cells, 0);
  EXPECT_GT(d.plan.makespan_s, 0.0);
  EXPECT_NEAR(d.achieved_s, r->makespan_s - t_f, 1e-9);

  // The failed robot stops at t_f and sweeps nothing after it: none of its
  // cells is among those left, and its path takes no longer than t_f.
  const FleetRobotRun& b = r->robots[1];
  EXPECT_TRUE(b.failed);
  ASSERT_EQ(b.legs.size(), 1u);
  EXPECT_TRUE(b.legs[0].interrupted);
  EXPECT_LE(b.finish_s, t_f + 1e-9);
  EXPECT_LE(b.legs[0].end_s, t_f + 1e-9);
  // Its driven path re-timed from rest to rest (drive_time_s) may add the
  // braking of a segment cut at t_f: at most max speed / acceleration.
  const RobotModel& model = o.fleet.robots[1].robot;
  EXPECT_LE(b.legs[0].run.drive_time_s + b.legs[0].run.stoppage_s,
            t_f + model.max_speed_mps / model.acceleration_mps2 + 1e-6);
  for (size_t i = 0; i < d.left.size(); ++i) {
    if (b.legs[0].run.swept[i]) {
      ASSERT_FALSE(d.left[i]) << "cell " << i;
    }
  }
  EXPECT_GT(b.swept_cells, 0);
  // The survivors' new plans start where they stood at t_f and together
  // cover every cell left then that the true map lets a robot reach.
  const std::vector<uint8_t> before = Reported(*r, true_grid, t_f);
  const std::vector<uint8_t> reachable = Reachable(known_grid, true_grid, o, &before);
  std::vector<uint8_t> planned(d.left.size(), 0);
  for (const FleetRobotPlan& rp : d.plan.robots) {
    for (const CoverageSweep& s : rp.result.plan.sweeps) {
      for (const CellIndex& c : s.cells) planned[true_grid.Index(c.row, c.col)] = 1;
    }
  }
  int64_t lost = 0;
  for (size_t i = 0; i < d.left.size(); ++i) lost += d.left[i] && reachable[i] && !planned[i];
  EXPECT_EQ(lost, 0) << "cells left at the failure that no survivor's plan sweeps";
  for (size_t k : {size_t{0}, size_t{2}}) {
    const FleetRobotRun& s = r->robots[k];
    ASSERT_EQ(s.legs.size(), 2u) << s.id;
    EXPECT_TRUE(s.legs[0].interrupted) << s.id;
    EXPECT_EQ(s.legs[1].start_s, t_f);
    const Waypoint& from = s.legs[0].run.driven.back();
    const Waypoint& to = s.legs[1].plan.path.front();
    EXPECT_NEAR(from.x, to.x, 1e-9);
    EXPECT_NEAR(from.y, to.y, 1e-9);
    EXPECT_GT(s.finish_s, t_f);
  }
}

TEST(FleetSimulation, TwoFailuresLeaveTheLastRobotEveryReachableCell) {
  const OccupancyMap known = testing::LoadShippedMap("small_rooms.yaml");
  absl::StatusOr<OccupancyMap> truth = AddClutter(known, 5.0, 2);
  ASSERT_TRUE(truth.ok()) << truth.status();
  FleetSimulationOptions o = OfficeFleet();
  o.fleet.base.common.time_limit_s = 0.3;
  o.fleet.robots = {Robot("a", 1.2, 1.2), Robot("b", 2.0, 3.0), Robot("c", 6.0, 6.0)};
  o.failures = {{"b", 40.0}, {"a", 20.0}};  // any order
  absl::StatusOr<FleetSimulationResult> r = SimulateFleet(known, *truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  Print(*r);
  EXPECT_TRUE(r->completed);
  EXPECT_EQ(r->unswept_reachable_cells, 0);
  ASSERT_EQ(r->redivisions.size(), 2u);
  EXPECT_EQ(r->redivisions[0].failed_robot, "a");
  EXPECT_THAT(r->redivisions[0].robots, ::testing::ElementsAre("b", "c"));
  EXPECT_EQ(r->redivisions[1].failed_robot, "b");
  EXPECT_THAT(r->redivisions[1].robots, ::testing::ElementsAre("c"));
  for (size_t k : {size_t{0}, size_t{1}}) {
    const FleetRobotRun& f = r->robots[k];
    EXPECT_TRUE(f.failed);
    for (const FleetLeg& leg : f.legs) EXPECT_LE(leg.end_s, f.failed_at_s + 1e-9) << f.id;
  }
  EXPECT_FALSE(r->robots[2].failed);
  EXPECT_DOUBLE_EQ(r->makespan_s, r->robots[2].finish_s);
}

TEST(FleetSimulation, BadFailuresAreRefusedNamingTheField) {
  const OccupancyMap known = testing::LoadShippedMap("small_rooms.yaml");
  FleetSimulationOptions o = OfficeFleet();
  o.fleet.robots = {Robot("a", 1.2, 1.2), Robot("b", 1.2, 2.2)};
  o.failures = {{"x", 10.0}};
  absl::StatusOr<FleetSimulationResult> r = SimulateFleet(known, known, o);
  EXPECT_THAT(r.status().message(), ::testing::HasSubstr("failures[0].robot_id: no robot 'x'"));
  o.failures = {{"a", 10.0}, {"a", 20.0}};
  r = SimulateFleet(known, known, o);
  EXPECT_THAT(r.status().message(), ::testing::HasSubstr("robot 'a' fails twice"));
  o.failures = {{"a", -1.0}};
  r = SimulateFleet(known, known, o);
  EXPECT_THAT(r.status().message(), ::testing::HasSubstr("failures[0].time_s"));
}

}  // namespace
}  // namespace covplan
