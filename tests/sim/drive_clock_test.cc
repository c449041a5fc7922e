// A drive stopped at a time of its own clock (RunUntil) never stands past
// that time: a fleet robot fails, or takes a new plan, exactly then. A
// replan mid-segment stops the robot where it stands, which takes longer
// than driving on (it brakes), so a drive advanced in small steps through a
// cluttered office must meet each bound with every replan it makes.
#include <cstdio>
#include <memory>
#include <vector>

#include "absl/strings/str_join.h"
#include "gtest/gtest.h"
#include "planner/sim/clutter.h"
#include "planner/sim/drive.h"
#include "planner/sim/run_setup.h"
#include "planner/sim/simulator.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using sim_internal::SimulatedDrive;

TEST(DriveClock, SmallStepsNeverCarryTheClockPastTheirBound) {
  const OccupancyMap office = testing::LoadShippedMap("sample_office.yaml");
  absl::StatusOr<OccupancyMap> truth = AddClutter(office, 10.0, 3);
  ASSERT_TRUE(truth.ok()) << truth.status();
  SimulationOptions o;
  o.method = ReplanMethod::kAuto;
  o.plan.robot.tool_width_m = 0.8;
  o.plan.time_limit_s = 0.3;
  o.replan_tour_time_limit_s = 0.1;
  sim_internal::LocalPlanSource source;
  absl::StatusOr<RetainedPlan> plan = source.InitialPlan(office, o.plan);
  ASSERT_TRUE(plan.ok()) << plan.status();
  std::vector<Point2> ends;
  for (const Waypoint* w : {&plan->plan.path.front(), &plan->plan.path.back()})
    ends.push_back({w->x, w->y});
  absl::StatusOr<sim_internal::TrueSite> site =
      sim_internal::MakeTrueSite(office, *truth, ends, o.plan);
  ASSERT_TRUE(site.ok()) << site.status();
  const std::shared_ptr<const Grid> drive_grid = plan->area->drive;
  absl::StatusOr<std::vector<uint8_t>> candidate =
      sim_internal::Candidates(*drive_grid, site->grid);
  ASSERT_TRUE(candidate.ok()) << candidate.status();
  SimulatedDrive drive(site->map(), site->grid, o, *std::move(plan), *std::move(candidate),
                       &source);

  // Bounds 0.05 s apart: shorter than any brake from cruising speed.
  double until = 0.0;
  int calls = 0;
  while (!drive.finished() && calls < 200000) {
    until += 0.05;
    ++calls;
    ASSERT_TRUE(drive.RunUntil(until).ok());
    ASSERT_LE(drive.clock_s(), until + 1e-9) << "after RunUntil(" << until << ")";
  }
  ASSERT_TRUE(drive.finished());
  const SimulationResult r = drive.Finish();
  std::printf("%d bounds, %d replans, total %.1f s\n", calls, r.num_replans, r.total_time_s);
  EXPECT_TRUE(r.completed) << r.termination;
  EXPECT_GT(r.num_replans, 0);
  EXPECT_TRUE(r.problems.empty()) << absl::StrJoin(r.problems, "\n");
}

}  // namespace
}  // namespace covplan
