// A robot walled in on the replanner's grid: its own cell and every way
// out reported blocked (clutter all round it in the cell model). The
// replanner keeps one way out free and says so (robot_cell_kept_free); the
// simulated robot, which cannot drive into a cell it found blocked, stops
// there at once with a termination that says why, instead of asking for
// the same plan a hundred times.

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/sim/clutter.h"
#include "planner/sim/simulator.h"
#include "tests/sim/sim_checks.h"
#include "tests/testing/oarp_options.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

// Seed 373 of 8 % clutter on the shipped small rooms, driven with the greedy
// tour and greedy detours (no time limit decides anything: the run is the
// same on every machine), walls the robot in at its 11th replan (found by
// running seeds 1-1500; seed 490 is the other one).
TEST(WalledIn, TheRunStopsAtOnceAndSaysWhy) {
  const OccupancyMap rooms = testing::LoadShippedMap("small_rooms.yaml");
  ClutterOptions clutter;
  clutter.keep_connected_cell_m = 0.8;
  absl::StatusOr<OccupancyMap> truth = AddClutter(rooms, 8.0, 373, clutter);
  ASSERT_TRUE(truth.ok()) << truth.status();
  SimulationOptions o;
  o.method = ReplanMethod::kGreedyDetour;
  o.plan.robot.tool_width_m = 0.8;
  o.plan.options = testing::OarpOptionsWith(TourSolver::kGreedy);
  absl::StatusOr<SimulationResult> r = Simulate(rooms, *truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_FALSE(r->completed);
  EXPECT_THAT(r->termination, ::testing::HasSubstr("walled in"));
  EXPECT_THAT(r->termination, ::testing::HasSubstr("robot_cell_kept_free"));
  // Before: the same plan was asked for until 100 of them had entered the
  // blocked cell, each listed as a problem.
  EXPECT_LT(r->num_replans, 20);
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  EXPECT_EQ(testing::FirstBlockedPoint(
                testing::TrueGrid(r->truth_used != nullptr ? *r->truth_used : *truth), r->driven),
            "");
}

}  // namespace
}  // namespace covplan
