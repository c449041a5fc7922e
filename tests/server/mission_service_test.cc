// UpdateMission and GetMission in process: three robots planned by
// PlanFleet on the shipped office; robot b stops for good a third of the
// way along its plan, and a and c get new plans (new plan ids) whose sweeps
// hold everything b had left (from its request's progress, or else from
// the progress its Drive session recorded); the mission then shows b stopped and a, c on
// their new plans, which GetPlan returns. A joining robot gets a share;
// unknown missions are NOT_FOUND, unknown robots INVALID_ARGUMENT naming
// the field. A mission and its updates survive a server restart. With
// Drive sessions open, an obstacle one robot reports reaches the others'
// streams as a new plan, and a redivision is pushed onto them. An obstacle
// one robot reported is kept out of every plan a redivision makes.
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/mission_fixture.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

using testing::MissionServiceTest;
using testing::SweptCells;

TEST_F(MissionServiceTest, AStoppedRobotsRemainderGoesToTheOthers) {
  PlanThree();
  const v1::PlanResponse& b = fleet_.robots(1).plan();
  // b stops for good a third of the way along its plan.
  const int k = std::max(1, b.path_size() / 3);
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* stop = update.add_robots();
  stop->set_robot_id("b");
  stop->set_stopped(true);
  stop->mutable_progress()->set_waypoint(k);
  stop->mutable_progress()->mutable_position()->set_x(b.path(k - 1).x());
  stop->mutable_progress()->mutable_position()->set_y(b.path(k - 1).y());
  v1::UpdateMissionResponse updated;
  grpc::Status status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(updated.mission_id(), fleet_.mission_id());
  ASSERT_EQ(updated.robots_size(), 2);
  EXPECT_EQ(updated.robots(0).id(), "a");
  EXPECT_EQ(updated.robots(1).id(), "c");
  EXPECT_GT(updated.handed_over_cells(), 0);
  EXPECT_GE(updated.remaining_cells(), updated.handed_over_cells());
  EXPECT_EQ(updated.cut_off_cells(), 0);
  EXPECT_GT(updated.makespan_s(), 0.0);
  std::set<std::string> old_ids;
  for (const v1::FleetRobotPlan& robot : fleet_.robots()) old_ids.insert(robot.plan().plan_id());
  std::set<int> together;
  for (const v1::FleetRobotPlan& robot : updated.robots()) {
    EXPECT_FALSE(robot.plan().plan_id().empty());
    EXPECT_EQ(old_ids.count(robot.plan().plan_id()), 0u) << robot.id();
    EXPECT_EQ(robot.plan().map_id(), map_id_);
    for (int cell : SweptCells(robot.plan())) together.insert(cell);
  }
  // Everything b would have swept after waypoint k (and had not swept by
  // then) is in a's or c's new plan.
  std::set<int> before;
  for (const v1::CoverageSweep& s : b.sweeps()) {
    if (s.waypoint() <= k) before.insert(s.cells().begin(), s.cells().end());
  }
  int handed = 0;
  for (const v1::CoverageSweep& s : b.sweeps()) {
    if (s.waypoint() <= k) continue;
    for (int cell : s.cells()) {
      if (before.count(cell)) continue;
      ++handed;
      EXPECT_TRUE(together.count(cell)) << "cell " << cell << " of b's remainder swept by none";
    }
  }
  EXPECT_GT(handed, 0);

  // The mission: b stopped, a and c on their new plans.
  v1::GetMissionResponse mission;
  status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(mission.map_id(), map_id_);
  ASSERT_EQ(mission.robots_size(), 3);
  EXPECT_EQ(mission.robots(0).robot_id(), "a");
  EXPECT_EQ(mission.robots(0).plan_id(), updated.robots(0).plan().plan_id());
  EXPECT_FALSE(mission.robots(0).stopped());
  EXPECT_EQ(mission.robots(1).robot_id(), "b");
  EXPECT_EQ(mission.robots(1).plan_id(), b.plan_id());
  EXPECT_TRUE(mission.robots(1).stopped());
  EXPECT_EQ(mission.robots(2).robot_id(), "c");
  EXPECT_EQ(mission.robots(2).plan_id(), updated.robots(1).plan().plan_id());
  EXPECT_FALSE(mission.robots(2).stopped());

  // A new plan is retained like any plan.
  v1::PlanResponse retained;
  status = GetPlan(updated.robots(0).plan().plan_id(), &retained);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(retained.SerializeAsString(), updated.robots(0).plan().SerializeAsString());

  // b stopped for good: it is not an active robot again.
  v1::UpdateMissionRequest again;
  again.set_mission_id(fleet_.mission_id());
  again.add_robots()->set_robot_id("b");
  status = Update(again, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("robots[0].robot_id"));
}

TEST_F(MissionServiceTest, AMissionAndItsUpdatesSurviveARestart) {
  PlanThree();
  ASSERT_NO_FATAL_FAILURE(Restart());
  v1::GetMissionResponse mission;
  grpc::Status status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(mission.map_id(), map_id_);
  ASSERT_EQ(mission.robots_size(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(mission.robots(i).robot_id(), fleet_.robots(i).id());
    EXPECT_EQ(mission.robots(i).plan_id(), fleet_.robots(i).plan().plan_id());
    EXPECT_FALSE(mission.robots(i).stopped());
  }
  // The restarted server redivides it: b stops half-way along its plan.
  const v1::PlanResponse& b = fleet_.robots(1).plan();
  const int k = std::max(1, b.path_size() / 2);
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* stop = update.add_robots();
  stop->set_robot_id("b");
  stop->set_stopped(true);
  stop->mutable_progress()->set_waypoint(k);
  stop->mutable_progress()->mutable_position()->set_x(b.path(k - 1).x());
  stop->mutable_progress()->mutable_position()->set_y(b.path(k - 1).y());
  v1::UpdateMissionResponse updated;
  status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(updated.robots_size(), 2);
  EXPECT_GT(updated.handed_over_cells(), 0);
  // And the update survives the next restart.
  ASSERT_NO_FATAL_FAILURE(Restart());
  status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(mission.robots_size(), 3);
  EXPECT_EQ(mission.robots(0).plan_id(), updated.robots(0).plan().plan_id());
  EXPECT_TRUE(mission.robots(1).stopped());
  EXPECT_EQ(mission.robots(2).plan_id(), updated.robots(1).plan().plan_id());
  // A mission id is not a plan id.
  v1::PlanResponse plan;
  EXPECT_EQ(GetPlan(fleet_.mission_id(), &plan).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(MissionServiceTest, TheAccountAddsUpAndIsCompleteOnlyWhenNothingIsLeft) {
  PlanThree();
  v1::GetMissionResponse mission;
  grpc::Status status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(mission.covered_cells(), 0);
  EXPECT_EQ(mission.remaining_cells(), fleet_.covered_cells());
  EXPECT_FALSE(mission.complete());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(mission.robots(i).remaining_cells(),
              static_cast<int64_t>(SweptCells(fleet_.robots(i).plan()).size()));
  }
  // b stops a third of the way along: what it swept stays its own.
  const v1::PlanResponse& b = fleet_.robots(1).plan();
  const int k = std::max(1, b.path_size() / 3);
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* stop = update.add_robots();
  stop->set_robot_id("b");
  stop->set_stopped(true);
  stop->mutable_progress()->set_waypoint(k);
  stop->mutable_progress()->mutable_position()->set_x(b.path(k - 1).x());
  stop->mutable_progress()->mutable_position()->set_y(b.path(k - 1).y());
  v1::UpdateMissionResponse updated;
  status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(mission.robots(1).covered_cells(), 0);
  EXPECT_EQ(mission.robots(1).remaining_cells(), 0);
  EXPECT_EQ(mission.remaining_cells(), updated.remaining_cells());
  EXPECT_EQ(mission.covered_cells() + mission.remaining_cells() + mission.cut_off_cells(),
            fleet_.cover_cells());
  EXPECT_FALSE(mission.complete());
  // a and c report that they reached the ends of their new plans.
  for (const v1::FleetRobotPlan& robot : updated.robots()) {
    Session s = OpenDrive(robot.plan().plan_id());
    const int n = robot.plan().path_size();
    v1::DriveRequest at_end;
    at_end.set_sequence(2);
    at_end.mutable_progress()->set_waypoint(n - 1);
    at_end.mutable_progress()->mutable_position()->set_x(robot.plan().path(n - 1).x());
    at_end.mutable_progress()->mutable_position()->set_y(robot.plan().path(n - 1).y());
    ASSERT_TRUE(s.stream->Write(at_end));
    Close(s);  // the server has read (and recorded) it once the call ends
  }
  status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(mission.remaining_cells(), 0);
  EXPECT_TRUE(mission.complete());
  EXPECT_EQ(mission.covered_cells() + mission.cut_off_cells(), fleet_.cover_cells());
}

TEST_F(MissionServiceTest, AnObstacleOneRobotSeesIsReplannedIntoTheOthersStreams) {
  PlanThree();
  const v1::PlanResponse& a = fleet_.robots(0).plan();
  const v1::PlanResponse& c = fleet_.robots(2).plan();
  Session sa = OpenDrive(a.plan_id());
  Session sc = OpenDrive(c.plan_id());
  // a sees an obstacle on a cell c sweeps near the end of its plan.
  const int cell = c.sweeps(c.sweeps_size() - 1).cells(0);
  v1::DriveRequest seen;
  seen.set_sequence(2);
  seen.mutable_progress()->set_waypoint(1);
  seen.mutable_progress()->mutable_position()->set_x(a.path(0).x());
  seen.mutable_progress()->mutable_position()->set_y(a.path(0).y());
  v1::CellRef* blocked = seen.mutable_obstacles()->add_cells();
  blocked->set_row(cell / c.grid().cols());
  blocked->set_col(cell % c.grid().cols());
  ASSERT_TRUE(sa.stream->Write(seen));
  v1::DriveEvent own;
  ASSERT_TRUE(sa.stream->Read(&own));
  ASSERT_TRUE(own.has_replan()) << own.DebugString();
  EXPECT_EQ(own.sequence(), 2u);
  EXPECT_FALSE(own.has_mission());
  // c's stream gets a new plan around it, unasked.
  v1::DriveEvent pushed;
  ASSERT_TRUE(sc.stream->Read(&pushed));
  ASSERT_TRUE(pushed.has_replan()) << pushed.DebugString();
  EXPECT_EQ(pushed.sequence(), 0u);
  EXPECT_EQ(pushed.mission().mission_id(), fleet_.mission_id());
  EXPECT_EQ(pushed.mission().cause(), v1::MissionNotice::SHARED_OBSTACLE);
  EXPECT_EQ(pushed.mission().from_robot(), "a");
  const v1::PlanResponse& c2 = pushed.replan().plan();
  EXPECT_NE(c2.plan_id(), c.plan_id());
  EXPECT_EQ(SweptCells(c2).count(cell), 0u) << "the new plan sweeps the blocked cell";
  EXPECT_GT(pushed.replan().replan().num_encounters(), 0);
  // The mission follows both robots onto their new plans.
  v1::GetMissionResponse mission;
  ASSERT_TRUE(GetMission(fleet_.mission_id(), &mission).ok());
  EXPECT_EQ(mission.robots(0).plan_id(), own.replan().plan().plan_id());
  EXPECT_EQ(mission.robots(1).plan_id(), fleet_.robots(1).plan().plan_id());
  EXPECT_EQ(mission.robots(2).plan_id(), c2.plan_id());
  Close(sa);
  Close(sc);
}

// Robot a reports (Replan) an obstacle on cells robot c sweeps near the end
// of its plan; c's plan never learns of it, and c then stops for good. The
// robots that take over c's cells neither sweep nor drive there.
TEST_F(MissionServiceTest, ARedivisionKeepsOutOfTheObstaclesTheRobotsReported) {
  PlanThree();
  const v1::PlanResponse& a = fleet_.robots(0).plan();
  const v1::PlanResponse& c = fleet_.robots(2).plan();
  const v1::CoverageSweep& late = c.sweeps(c.sweeps_size() - 2);
  ASSERT_GE(late.cells_size(), 1);
  std::set<int> blocked(late.cells().begin(),
                        late.cells().begin() + std::min(3, late.cells_size()));
  v1::ReplanRequest seen;
  seen.set_plan_id(a.plan_id());
  seen.mutable_progress()->set_waypoint(1);
  seen.mutable_progress()->mutable_position()->set_x(a.path(0).x());
  seen.mutable_progress()->mutable_position()->set_y(a.path(0).y());
  for (int cell : blocked) {
    v1::CellRef* ref = seen.mutable_obstacles()->add_cells();
    ref->set_row(cell / c.grid().cols());
    ref->set_col(cell % c.grid().cols());
  }
  v1::ReplanResponse a2;
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    grpc::Status status = stub_->Replan(&context, seen, &a2);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* stop = update.add_robots();
  stop->set_robot_id("c");
  stop->set_stopped(true);
  const int k = std::max(1, c.path_size() / 3);
  stop->mutable_progress()->set_waypoint(k);
  stop->mutable_progress()->mutable_position()->set_x(c.path(k - 1).x());
  stop->mutable_progress()->mutable_position()->set_y(c.path(k - 1).y());
  v1::UpdateMissionResponse updated;
  grpc::Status status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(updated.robots_size(), 2);
  EXPECT_GE(updated.cut_off_cells(), static_cast<int>(blocked.size()));
  for (const v1::FleetRobotPlan& robot : updated.robots()) {
    const v1::PlanResponse& p = robot.plan();
    for (int cell : SweptCells(p)) {
      EXPECT_EQ(blocked.count(cell), 0u) << robot.id() << " sweeps blocked cell " << cell;
    }
    // Every point of the path (sampled at 1/20 of a cell) lies outside the
    // blocked cells.
    const v1::Grid& g = p.grid();
    for (int i = 1; i < p.path_size(); ++i) {
      const v1::Waypoint &u = p.path(i - 1), &v = p.path(i);
      const double len = std::hypot(v.x() - u.x(), v.y() - u.y());
      const int steps = 1 + static_cast<int>(20.0 * len / g.cell_size_m());
      for (int s = 0; s <= steps; ++s) {
        const double t = static_cast<double>(s) / steps;
        const int col = static_cast<int>(
            std::floor((u.x() + t * (v.x() - u.x()) - g.origin_x_m()) / g.cell_size_m()));
        const int row = static_cast<int>(
            std::floor((u.y() + t * (v.y() - u.y()) - g.origin_y_m()) / g.cell_size_m()));
        ASSERT_EQ(blocked.count(row * g.cols() + col), 0u)
            << robot.id() << " drives through blocked cell (" << row << ", " << col << ")";
      }
    }
  }
}

TEST_F(MissionServiceTest, ARedivisionIsPushedOntoTheRobotsStreams) {
  PlanThree();
  Session sa = OpenDrive(fleet_.robots(0).plan().plan_id());
  Session sc = OpenDrive(fleet_.robots(2).plan().plan_id());
  const v1::PlanResponse& b = fleet_.robots(1).plan();
  const int k = std::max(1, b.path_size() / 3);
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* stop = update.add_robots();
  stop->set_robot_id("b");
  stop->set_stopped(true);
  stop->mutable_progress()->set_waypoint(k);
  stop->mutable_progress()->mutable_position()->set_x(b.path(k - 1).x());
  stop->mutable_progress()->mutable_position()->set_y(b.path(k - 1).y());
  v1::UpdateMissionResponse updated;
  grpc::Status status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(updated.robots_size(), 2);
  Session* sessions[] = {&sa, &sc};
  for (int i = 0; i < 2; ++i) {
    v1::DriveEvent pushed;
    ASSERT_TRUE(sessions[i]->stream->Read(&pushed)) << updated.robots(i).id();
    ASSERT_TRUE(pushed.has_replan()) << pushed.DebugString();
    EXPECT_EQ(pushed.sequence(), 0u);
    EXPECT_EQ(pushed.mission().cause(), v1::MissionNotice::REDIVIDED);
    EXPECT_EQ(pushed.replan().plan().SerializeAsString(),
              updated.robots(i).plan().SerializeAsString());
  }
  // The session drives the pushed plan: an observation on it is replanned.
  const v1::PlanResponse& a2 = updated.robots(0).plan();
  v1::DriveRequest seen;
  seen.set_plan_id(a2.plan_id());
  seen.set_sequence(2);
  seen.mutable_progress()->set_waypoint(1);
  seen.mutable_progress()->mutable_position()->set_x(a2.path(0).x());
  seen.mutable_progress()->mutable_position()->set_y(a2.path(0).y());
  const int cell = a2.sweeps(a2.sweeps_size() - 1).cells(0);
  v1::CellRef* blocked = seen.mutable_obstacles()->add_cells();
  blocked->set_row(cell / a2.grid().cols());
  blocked->set_col(cell % a2.grid().cols());
  ASSERT_TRUE(sa.stream->Write(seen));
  v1::DriveEvent own;
  ASSERT_TRUE(sa.stream->Read(&own));
  ASSERT_TRUE(own.has_replan()) << own.DebugString();
  EXPECT_EQ(own.sequence(), 2u);
  EXPECT_EQ(SweptCells(own.replan().plan()).count(cell), 0u);
  Close(sa);
  // c's stream also hears of a's obstacle, if it touches c's new plan.
  sc.stream->WritesDone();
  v1::DriveEvent rest;
  while (sc.stream->Read(&rest)) {
    EXPECT_EQ(rest.mission().cause(), v1::MissionNotice::SHARED_OBSTACLE) << rest.DebugString();
  }
  EXPECT_TRUE(sc.stream->Finish().ok());
}

TEST_F(MissionServiceTest, AJoiningRobotGetsAShare) {
  PlanThree();
  const v1::PlanResponse& a = fleet_.robots(0).plan();
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* join = update.add_robots();
  join->set_robot_id("d");
  join->mutable_joining()->mutable_robot()->set_tool_width_m(0.8);
  // It joins where a started.
  join->mutable_joining()->mutable_robot()->mutable_start()->set_x(a.path(0).x());
  join->mutable_joining()->mutable_robot()->mutable_start()->set_y(a.path(0).y());
  v1::UpdateMissionResponse updated;
  grpc::Status status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(updated.robots_size(), 4);
  EXPECT_EQ(updated.handed_over_cells(), 0);
  EXPECT_EQ(updated.robots(3).id(), "d");
  EXPECT_FALSE(updated.robots(3).idle());
  EXPECT_FALSE(SweptCells(updated.robots(3).plan()).empty());
  v1::GetMissionResponse mission;
  status = GetMission(fleet_.mission_id(), &mission);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(mission.robots_size(), 4);
  EXPECT_EQ(mission.robots(3).robot_id(), "d");
  EXPECT_EQ(mission.robots(3).plan_id(), updated.robots(3).plan().plan_id());

  // Its id is taken now.
  status = Update(update, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("robots[0].robot_id"));
}

TEST_F(MissionServiceTest, WithoutProgressTheDriveSessionsRecordedProgressCounts) {
  PlanThree();
  const v1::PlanResponse& b = fleet_.robots(1).plan();
  const int k = std::max(1, b.path_size() / 3);
  // b reports a third of its plan driven in a Drive session, then stops.
  {
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientReaderWriter<v1::DriveRequest, v1::DriveEvent>> stream =
        stub_->Drive(&context);
    v1::DriveRequest first;
    first.set_plan_id(b.plan_id());
    first.set_sequence(1);
    ASSERT_TRUE(stream->Write(first));
    v1::DriveEvent event;
    ASSERT_TRUE(stream->Read(&event));
    ASSERT_TRUE(event.has_ready()) << event.DebugString();
    v1::DriveRequest report;
    report.set_sequence(2);
    report.mutable_progress()->set_waypoint(k);
    report.mutable_progress()->mutable_position()->set_x(b.path(k - 1).x());
    report.mutable_progress()->mutable_position()->set_y(b.path(k - 1).y());
    ASSERT_TRUE(stream->Write(report));
    stream->WritesDone();
    EXPECT_TRUE(stream->Finish().ok());
  }
  v1::UpdateMissionRequest update;
  update.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* stop = update.add_robots();
  stop->set_robot_id("b");
  stop->set_stopped(true);
  v1::UpdateMissionResponse updated;
  grpc::Status status = Update(update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  // At most what b had left from waypoint k on, not its whole share.
  std::set<int> done;
  for (const v1::CoverageSweep& s : b.sweeps()) {
    if (s.waypoint() < k) done.insert(s.cells().begin(), s.cells().end());
  }
  const std::set<int> all = SweptCells(b);
  EXPECT_GT(updated.handed_over_cells(), 0);
  EXPECT_LE(updated.handed_over_cells(), static_cast<int64_t>(all.size() - done.size()));
  EXPECT_GT(done.size(), 0u);
}

TEST_F(MissionServiceTest, UnknownMissionsAndRobotsAreRefused) {
  PlanThree();
  v1::UpdateMissionRequest update;
  update.set_mission_id("mission-0123456789abcdef");
  update.add_robots()->set_robot_id("a");
  v1::UpdateMissionResponse updated;
  grpc::Status status = Update(update, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(status.error_message(), HasSubstr("mission-0123456789abcdef"));
  v1::GetMissionResponse mission;
  status = GetMission("mission-0123456789abcdef", &mission);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);

  update.set_mission_id(fleet_.mission_id());
  update.add_robots()->set_robot_id("zz");
  status = Update(update, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("robots[1].robot_id"));
  EXPECT_THAT(status.error_message(), HasSubstr("zz"));

  update.mutable_robots(1)->set_robot_id("a");
  status = Update(update, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("robots[1].robot_id"));

  // Progress beyond the plan's end, named by the request's index.
  v1::UpdateMissionRequest far;
  far.set_mission_id(fleet_.mission_id());
  v1::MissionRobotUpdate* c = far.add_robots();
  c->set_robot_id("c");
  c->mutable_progress()->set_waypoint(fleet_.robots(2).plan().path_size() + 10);
  c->mutable_progress()->mutable_position()->set_x(1.0);
  status = Update(far, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("robots[0] ('c')"));
}

}  // namespace
}  // namespace covplan
