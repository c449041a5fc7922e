// The Replan RPC in process: by plan_id and inline, chained replans, honest
// accounting, malformed progress and obstacles, a short deadline answered in
// time, the estimator kept across a restart.
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "client/replan_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/plan_checks.h"
#include "tests/testing/timing.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

class ReplanServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / absl::StrCat("covplan_replan_", ::getpid()))
               .string();
    Start();
    absl::StatusOr<v1::Map> map =
        MapProtoFromFile(absl::StrCat(COVPLAN_SOURCE_DIR, "/maps/sample_office.yaml"),
                         MapFileOverrides(), EngineLimits());
    ASSERT_TRUE(map.ok()) << map.status();
    map_ = *map;
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }
  void Start(const std::string& replica = "") {
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.store_dir = dir_ + "/maps";
    config.service.replica = replica;
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_->port()), grpc::InsecureChannelCredentials()));
  }
  v1::PlanRequest PlanRequestForOffice() {
    v1::PlanRequest r;
    *r.mutable_map() = map_;
    r.mutable_robot()->set_tool_width_m(0.8);
    r.set_time_limit_s(0.5);
    return r;
  }
  grpc::Status Plan(const v1::PlanRequest& request, v1::PlanResponse* out) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->Plan(&context, request, out);
  }
  grpc::Status Replan(const v1::ReplanRequest& request, v1::ReplanResponse* out,
                      std::chrono::milliseconds deadline = std::chrono::seconds(30)) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + deadline);
    return stub_->Replan(&context, request, out);
  }
  // The robot a sixth of the way along, meeting a 1.2 m box in the corridor.
  static v1::ReplanRequest RequestFor(const v1::PlanResponse& plan) {
    v1::ReplanRequest r;
    r.set_plan_id(plan.plan_id());
    const int k = plan.path_size() / 6;
    r.mutable_progress()->set_waypoint(k);
    r.mutable_progress()->mutable_position()->set_x(plan.path(k - 1).x());
    r.mutable_progress()->mutable_position()->set_y(plan.path(k - 1).y());
    v1::Ring* ring = r.mutable_obstacles()->add_polygons()->mutable_outer();
    for (auto [x, y] : {std::pair{9.0, 9.2}, {10.2, 9.2}, {10.2, 10.0}, {9.0, 10.0}, {9.0, 9.2}}) {
      v1::Point2* p = ring->add_points();
      p->set_x(x);
      p->set_y(y);
    }
    return r;
  }
  static int Swept(const v1::PlanResponse& plan) {
    std::set<int> cells;
    for (const v1::CoverageSweep& s : plan.sweeps())
      cells.insert(s.cells().begin(), s.cells().end());
    return static_cast<int>(cells.size());
  }

  std::string dir_;
  v1::Map map_;
  std::unique_ptr<CovplanServer> server_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(ReplanServiceTest, ReplansByPlanIdAndInlineAndChains) {
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestForOffice(), &plan).ok());
  const v1::ReplanRequest request = RequestFor(plan);
  v1::ReplanResponse by_id;
  grpc::Status status = Replan(request, &by_id);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const v1::ReplanStats& s = by_id.replan();
  EXPECT_GT(s.newly_blocked_cells(), 0);
  EXPECT_GT(s.num_encounters(), 0);
  EXPECT_EQ(Swept(by_id.plan()), s.remaining_cells());  // everything left is swept
  EXPECT_EQ(by_id.plan().stats().covered_cells(), s.remaining_cells());
  EXPECT_EQ(s.complete(), s.newly_unreachable_cells() == 0);
  EXPECT_NE(by_id.plan().plan_id(), plan.plan_id());
  testing::ExpectArrivalTimes(by_id.plan());
  EXPECT_NEAR(by_id.plan().path(0).x(), request.progress().position().x(), 1e-9);
  EXPECT_NEAR(by_id.plan().path(by_id.plan().path_size() - 1).x(),
              plan.path(plan.path_size() - 1).x(), 1e-9);
  // The new plan is retained: GetPlan and a second replan continue from it.
  {
    grpc::ClientContext context;
    v1::GetPlanRequest get;
    get.set_plan_id(by_id.plan().plan_id());
    v1::PlanResponse retained;
    ASSERT_TRUE(stub_->GetPlan(&context, get, &retained).ok());
    EXPECT_EQ(retained.path_size(), by_id.plan().path_size());
  }
  v1::ReplanRequest again = RequestFor(by_id.plan());
  again.mutable_obstacles()->clear_polygons();
  v1::CellRef* cell = again.mutable_obstacles()->add_cells();
  const int last = by_id.plan().sweeps(by_id.plan().sweeps_size() - 1).cells(0);
  cell->set_row(last / by_id.plan().grid().cols());
  cell->set_col(last % by_id.plan().grid().cols());
  v1::ReplanResponse second;
  status = Replan(again, &second);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(Swept(second.plan()), second.replan().remaining_cells());
  EXPECT_LT(second.replan().remaining_cells(), s.remaining_cells());
  // The mission's account adds up over the chain: what this plan covers, what
  // earlier plans swept, and what obstacles cut off are the first plan's cells.
  EXPECT_EQ(by_id.plan().stats().mission_covered_cells(), s.covered_cells_before());
  EXPECT_EQ(second.plan().stats().mission_covered_cells(),
            s.covered_cells_before() + second.replan().covered_cells_before());
  EXPECT_EQ(second.plan().stats().mission_cut_off_cells(),
            s.newly_unreachable_cells() + second.replan().newly_unreachable_cells());
  EXPECT_EQ(second.plan().stats().mission_obstructed_cells(),
            s.newly_obstructed_cells() + second.replan().newly_obstructed_cells());
  EXPECT_GT(s.newly_obstructed_cells(), 0);  // the box stands on cells still to cover
  EXPECT_EQ(second.plan().stats().free_cells() + second.plan().stats().mission_covered_cells() +
                second.plan().stats().mission_cut_off_cells() +
                second.plan().stats().mission_obstructed_cells(),
            plan.stats().free_cells());
  // The same chain from the client's inline copy of the replanned plan.
  {
    v1::ReplanRequest inline_again = again;
    inline_again.clear_plan_id();
    *inline_again.mutable_plan()->mutable_request() = PlanRequestForOffice();
    *inline_again.mutable_plan()->mutable_plan() = by_id.plan();
    v1::ReplanResponse from_inline;
    status = Replan(inline_again, &from_inline);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(from_inline.replan().remaining_cells(), second.replan().remaining_cells());
    EXPECT_EQ(from_inline.plan().stats().mission_covered_cells(),
              second.plan().stats().mission_covered_cells());
    EXPECT_EQ(from_inline.plan().stats().unreachable_free_cells(),
              second.plan().stats().unreachable_free_cells());
  }

  // Inline: the client's copy of the plan and its request.
  v1::ReplanRequest inline_request = request;
  *inline_request.mutable_plan()->mutable_request() = PlanRequestForOffice();
  *inline_request.mutable_plan()->mutable_plan() = plan;
  v1::ReplanResponse inlined;
  status = Replan(inline_request, &inlined);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(inlined.replan().remaining_cells(), s.remaining_cells());
  EXPECT_EQ(inlined.replan().newly_blocked_cells(), s.newly_blocked_cells());
  EXPECT_EQ(Swept(inlined.plan()), inlined.replan().remaining_cells());
}

TEST_F(ReplanServiceTest, MalformedRequestsAreInvalidArgumentOrNotFound) {
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestForOffice(), &plan).ok());
  struct Case {
    v1::ReplanRequest request;
    grpc::StatusCode code;
    const char* message;
  };
  std::vector<Case> cases;
  v1::ReplanRequest r = RequestFor(plan);
  r.mutable_progress()->set_waypoint(plan.path_size() + 5);
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "progress.waypoint"});
  r = RequestFor(plan);
  r.mutable_progress()->mutable_position()->set_x(std::nan(""));
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "progress.position"});
  r = RequestFor(plan);
  r.mutable_progress()->mutable_position()->set_y(500);
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "from segment"});
  r = RequestFor(plan);
  r.mutable_progress()->clear_position();
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "progress.position is required"});
  r = RequestFor(plan);
  r.mutable_obstacles()->add_cells()->set_row(-4);
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "obstacles.cells[0]"});
  r = RequestFor(plan);
  r.mutable_obstacles()->mutable_polygons(0)->mutable_outer()->mutable_points()->RemoveLast();
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "obstacles.polygons[0].outer"});
  r = RequestFor(plan);
  r.set_method(static_cast<v1::ReplanMethod>(77));
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "method"});
  r = RequestFor(plan);
  r.set_plan_id("p-nope");
  cases.push_back({r, grpc::StatusCode::NOT_FOUND, "unknown or expired plan_id"});
  r = RequestFor(plan);
  r.clear_plan_id();
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "needs plan_id"});
  for (size_t i = 0; i < cases.size(); ++i) {
    v1::ReplanResponse out;
    const grpc::Status status = Replan(cases[i].request, &out);
    EXPECT_EQ(status.error_code(), cases[i].code) << i << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(cases[i].message)) << i;
  }
}

TEST_F(ReplanServiceTest, AShortDeadlineIsAnsweredInTimeWithAPlan) {
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestForOffice(), &plan).ok());
  // 150 ms, proportionally longer under sanitizers (testing::kTimingSlowdown).
  const std::chrono::milliseconds deadline(static_cast<int64_t>(150 * testing::kTimingSlowdown));
  for (v1::ReplanMethod method : {v1::AUTO, v1::ILP1, v1::FULL}) {
    v1::ReplanRequest request = RequestFor(plan);
    request.set_method(method);
    v1::ReplanResponse out;
    const auto start = std::chrono::steady_clock::now();
    const grpc::Status status = Replan(request, &out, deadline);
    const auto elapsed = std::chrono::steady_clock::now() - start;
    ASSERT_TRUE(status.ok()) << v1::ReplanMethod_Name(method) << ": " << status.error_message();
    EXPECT_LT(elapsed, deadline);
    EXPECT_EQ(Swept(out.plan()), out.replan().remaining_cells()) << v1::ReplanMethod_Name(method);
  }
}

TEST_F(ReplanServiceTest, TheEstimatorIsKeptAcrossRestarts) {
  // The greedy tour does not depend on how far a timed search got, so the
  // box meets the same uncovered ranks in every build and the replan that
  // repartitions them teaches the estimator a sample.
  v1::PlanRequest request = PlanRequestForOffice();
  request.set_tour_solver(v1::GREEDY);
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(request, &plan).ok());
  v1::ReplanResponse out;
  ASSERT_TRUE(Replan(RequestFor(plan), &out).ok());
  ASSERT_GE(out.replan().replanned_encounter(), 0) << out.replan().method();
  ASSERT_GT(out.replan().new_ranks(), 0) << out.replan().method();
  const int64_t samples = server_->service().estimator().num_samples();
  EXPECT_GE(samples, 1);
  server_.reset();
  Start();
  EXPECT_EQ(server_->service().estimator().num_samples(), samples);
}

// Replicas sharing a store keep their estimators apart: each saves under
// its own name (a replica's first run starts from what a server alone
// learned), so none overwrites another's.
TEST_F(ReplanServiceTest, EachReplicaKeepsItsOwnEstimator) {
  v1::PlanRequest request = PlanRequestForOffice();
  request.set_tour_solver(v1::GREEDY);
  const auto learn = [&] {
    v1::PlanResponse plan;
    ASSERT_TRUE(Plan(request, &plan).ok());
    v1::ReplanResponse out;
    ASSERT_TRUE(Replan(RequestFor(plan), &out).ok());
    ASSERT_GT(out.replan().new_ranks(), 0) << out.replan().method();
  };
  learn();
  const int64_t alone = server_->service().estimator().num_samples();
  ASSERT_GE(alone, 1);
  server_.reset();
  Start("r1");
  EXPECT_EQ(server_->service().estimator().num_samples(), alone);  // seeded
  learn();
  learn();
  const int64_t r1 = server_->service().estimator().num_samples();
  EXPECT_GT(r1, alone);
  server_.reset();
  Start("r2");
  EXPECT_EQ(server_->service().estimator().num_samples(), alone);  // not r1's
  learn();
  server_.reset();
  Start("r1");
  EXPECT_EQ(server_->service().estimator().num_samples(), r1);  // not overwritten by r2
  server_.reset();
  Start();
  EXPECT_EQ(server_->service().estimator().num_samples(), alone);
}

TEST_F(ReplanServiceTest, TheReplanCommandTalksToTheServer) {
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestForOffice(), &plan).ok());
  const v1::ReplanRequest r = RequestFor(plan);
  const std::string out = dir_ + "/replanned.json";
  const std::string server = absl::StrCat("127.0.0.1:", server_->port());
  ASSERT_EQ(RunReplanCommand(
                {"--server", server, "--plan-id", plan.plan_id(), "--waypoint",
                 absl::StrCat(r.progress().waypoint()), "--at",
                 absl::StrCat(r.progress().position().x(), ",", r.progress().position().y()),
                 "--obstacle", "9,9.2 10.2,9.2 10.2,10 9,10", "--method", "ilp2", "--out", out}),
            0);
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_THAT(ss.str(), HasSubstr("\"sweeps\""));
  EXPECT_THAT(ss.str(), HasSubstr("\"planner\": \"oarp-replan\""));
  // Bad flags and server errors give a non-zero exit.
  EXPECT_NE(RunReplanCommand({"--server", server, "--plan-id", plan.plan_id()}), 0);
  EXPECT_NE(RunReplanCommand({"--server", server, "--plan-id", "p-unknown", "--distance", "3"}), 0);
  EXPECT_NE(RunReplanCommand({"--server", server, "--plan-id", plan.plan_id(), "--distance", "3",
                              "--method", "magic"}),
            0);
}

TEST_F(ReplanServiceTest, TheResumeCommandTalksToTheServer) {
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestForOffice(), &plan).ok());
  const std::string out = dir_ + "/resumed.json";
  const std::string server = absl::StrCat("127.0.0.1:", server_->port());
  const std::string dock = absl::StrCat(plan.path(0).x(), ",", plan.path(0).y(), ",0.5");
  ASSERT_EQ(RunResumeCommand({"--server", server, "--plan-id", plan.plan_id(), "--at", dock,
                              "--distance", "25", "--out", out}),
            0);
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_THAT(ss.str(), HasSubstr("\"sweeps\""));
  EXPECT_THAT(ss.str(), HasSubstr(absl::StrCat("\"x\": ", plan.path(0).x())));
  // Bad flags and server errors give a non-zero exit.
  EXPECT_NE(RunResumeCommand({"--server", server, "--plan-id", plan.plan_id()}), 0);  // no --at
  EXPECT_NE(RunResumeCommand({"--server", server, "--plan-id", plan.plan_id(), "--at", "1,2,3,4"}),
            0);
  EXPECT_NE(RunResumeCommand(
                {"--server", server, "--plan-id", plan.plan_id(), "--at", dock, "--waypoint", "3"}),
            0);
  EXPECT_NE(RunResumeCommand({"--server", server, "--plan-id", "p-unknown", "--at", dock}), 0);
}

// Hostile replans: every numeric field of progress and obstacles drawn from
// NaN, +-inf, 0, -0, huge, tiny and plausible values. Every reply is OK with a
// plan that sweeps what it claims, or INVALID_ARGUMENT / NOT_FOUND with a
// message; the server keeps answering.
TEST_F(ReplanServiceTest, RandomHostileReplansAreAnsweredNeverCrash) {
  v1::PlanResponse plan;
  ASSERT_TRUE(Plan(PlanRequestForOffice(), &plan).ok());
  std::mt19937 rng(7);
  const double nasty[] = {std::nan(""), INFINITY, -INFINITY, 0.0, -0.0,
                          1e300,        -1e300,   1e-300,    3.0, 12.5};
  auto pick = [&]() { return nasty[rng() % (sizeof(nasty) / sizeof(nasty[0]))]; };
  auto plausible = [&](int k, int axis) { return axis == 0 ? plan.path(k).x() : plan.path(k).y(); };
  int ok = 0, invalid = 0;
  for (int i = 0; i < 60; ++i) {
    v1::ReplanRequest r;
    r.set_plan_id(plan.plan_id());
    const int k = 1 + static_cast<int>(rng() % (plan.path_size() + 3));
    switch (rng() % 3) {
      case 0:
        r.mutable_progress()->set_waypoint(k);
        r.mutable_progress()->mutable_position()->set_x(
            rng() % 2 ? pick() : plausible(std::min(k, plan.path_size() - 1), 0));
        r.mutable_progress()->mutable_position()->set_y(
            rng() % 2 ? pick() : plausible(std::min(k, plan.path_size() - 1), 1));
        break;
      case 1:
        r.mutable_progress()->set_distance_m(rng() % 2 ? pick() : 7.0 * (rng() % 50));
        break;
      default:
        r.mutable_progress()->set_waypoint(static_cast<int>(rng() % 7) - 3);
    }
    if (rng() % 2) r.mutable_progress()->set_tolerance_m(pick());
    for (int n = rng() % 3; n > 0; --n) {
      v1::Point2* p = r.mutable_obstacles()->add_points();
      p->set_x(rng() % 2 ? pick() : 1.0 * (rng() % 28));
      p->set_y(rng() % 2 ? pick() : 1.0 * (rng() % 19));
    }
    for (int n = rng() % 2; n > 0; --n) {
      v1::CellRef* c = r.mutable_obstacles()->add_cells();
      c->set_row(static_cast<int>(rng() % 40) - 5);
      c->set_col(static_cast<int>(rng() % 50) - 5);
    }
    if (rng() % 3 == 0) {
      v1::Ring* ring = r.mutable_obstacles()->add_polygons()->mutable_outer();
      const double x = rng() % 2 ? pick() : 1.0 * (rng() % 27), y = 1.0 * (rng() % 18);
      for (auto [dx, dy] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 0.0}}) {
        v1::Point2* p = ring->add_points();
        p->set_x(x + dx);
        p->set_y(y + dy);
      }
    }
    r.set_method(static_cast<v1::ReplanMethod>(rng() % 7));
    v1::ReplanResponse out;
    const grpc::Status status = Replan(r, &out);
    if (status.ok()) {
      ++ok;
      EXPECT_EQ(Swept(out.plan()), out.replan().remaining_cells()) << i;
      for (const v1::Waypoint& w : out.plan().path()) {
        ASSERT_TRUE(std::isfinite(w.x()) && std::isfinite(w.y()) && std::isfinite(w.theta())) << i;
      }
    } else {
      ++invalid;
      EXPECT_THAT(status.error_code(),
                  ::testing::AnyOf(grpc::StatusCode::INVALID_ARGUMENT, grpc::StatusCode::NOT_FOUND))
          << i << ": " << status.error_message();
      EXPECT_FALSE(status.error_message().empty());
    }
  }
  EXPECT_GT(ok, 5);
  EXPECT_GT(invalid, 5);
  v1::ReplanResponse out;
  ASSERT_TRUE(Replan(RequestFor(plan), &out).ok());  // still serving
}

}  // namespace
}  // namespace covplan
