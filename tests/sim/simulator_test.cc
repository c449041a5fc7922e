// The replanning simulator on the shipped office: the robot plans the plain
// office and drives it through the furnished one. Every method finishes,
// never drives into a cell the true map blocks, keeps its time accounting
// (total = drive + stoppage, drive = the driven path under the robot model)
// and covers nearly what an offline plan of the true map covers. With a
// perfect map nothing is replanned and the run is the plan. Clutter hits its
// share and is reproducible; the CLI's JSON carries every figure.
#include "planner/sim/simulator.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "client/simulate_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/engine/engine.h"
#include "planner/grid/grid.h"
#include "planner/grid/map_io.h"
#include "planner/sim/clutter.h"
#include "tests/sim/sim_checks.h"
#include "tests/testing/oarp_options.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using testing::FirstBlockedPoint;
using testing::TrueGrid;

using ::testing::HasSubstr;

std::string MapPath(const std::string& name) {
  return std::string(COVPLAN_SOURCE_DIR) + "/maps/" + name;
}

OccupancyMap Load(const std::string& name) { return testing::LoadShippedMap(name); }

SimulationOptions Options(ReplanMethod method) {
  SimulationOptions o;
  o.method = method;
  o.plan.robot.tool_width_m = 0.8;
  o.plan.time_limit_s = 0.5;
  return o;
}

class EveryReplanMethod : public ::testing::TestWithParam<ReplanMethod> {};

TEST_P(EveryReplanMethod,
       DrivesTheFurnishedOfficeCoveringWhatAnOfflinePlanCoversWithoutEnteringFurniture) {
  const OccupancyMap known = Load("sample_office.yaml");
  const OccupancyMap truth = Load("sample_office_furnished.yaml");
  const SimulationOptions o = Options(GetParam());
  absl::StatusOr<SimulationResult> r = Simulate(known, truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  absl::StatusOr<OfflineBound> offline = OfflineLowerBound(truth, o.plan);
  ASSERT_TRUE(offline.ok()) << offline.status();
  absl::StatusOr<OccupancyMap> cells = CellLevelTruth(known, truth, o.plan);
  ASSERT_TRUE(cells.ok()) << cells.status();
  absl::StatusOr<OfflineBound> cell_bound = OfflineLowerBound(*cells, o.plan);
  ASSERT_TRUE(cell_bound.ok()) << cell_bound.status();
  std::printf(
      "%s: total %.1f s (drive %.1f, stoppage %.2f), planned %.1f, offline %.1f (cells %.1f); "
      "replans %d, encounters %d, detours %d, found %zu, touch %d; in obstacles %.2f m; "
      "coverage %.4f (offline %.4f)\n",
      ReplanMethodName(GetParam()), r->total_time_s, r->drive_time_s, r->stoppage_s,
      r->planned_duration_s, offline->duration_s, cell_bound->duration_s, r->num_replans,
      r->num_encounters, r->num_greedy_detours, r->obstacles_found.size(), r->num_touch_detections,
      r->length_in_obstacles_m, r->covered_free_area_ratio, offline->covered_free_area_ratio);
  for (const std::string& p : r->problems) std::printf("  problem: %s\n", p.c_str());

  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  EXPECT_GT(r->num_replans, 0);
  EXPECT_FALSE(r->obstacles_found.empty());
  // Never into furniture.
  const Grid true_grid = TrueGrid(truth);
  EXPECT_EQ(FirstBlockedPoint(true_grid, r->driven), "");
  // Nor through an obstacle smaller than its cell: the robot reports the
  // cell of one it meets (sight or touch), so every cell it reports holds
  // an obstacle, and it drives less than 0.1 % of its path through them
  // (issue 32's target; 0 m on this office).
  for (const CellIndex& c : r->obstacles_found) {
    EXPECT_TRUE(!true_grid.IsFree(c) || testing::CellHoldsObstacle(truth, true_grid, c))
        << "cell (" << c.row << ", " << c.col << ") holds no obstacle";
  }
  EXPECT_GT(r->num_small_obstacles, 0);
  EXPECT_LE(r->length_in_obstacles_m, 0.001 * r->path_length_m);
  // Time accounting.
  EXPECT_NEAR(r->total_time_s, r->drive_time_s + r->stoppage_s, 1e-9 * r->total_time_s);
  const PlanStats driven = ComputePathStats(r->driven, o.plan.robot);
  EXPECT_DOUBLE_EQ(r->drive_time_s, driven.estimated_duration_s);
  EXPECT_DOUBLE_EQ(r->path_length_m, driven.coverage_length_m + driven.transition_length_m);
  EXPECT_EQ(r->num_turns, driven.num_turns);
  EXPECT_GE(r->stoppage_s, 0.0);
  EXPECT_EQ(r->replan_ms.size(), static_cast<size_t>(r->num_replans));
  EXPECT_EQ(r->replan_points.size(), static_cast<size_t>(r->num_replans));
  EXPECT_EQ(r->replan_methods.size(), static_cast<size_t>(r->num_replans));
  EXPECT_LE(r->num_greedy_detours, r->num_encounters);
  if (GetParam() == ReplanMethod::kGreedyDetour) {
    // Every encounter is driven around, no compute time is charged.
    EXPECT_EQ(r->num_greedy_detours, r->num_encounters);
    EXPECT_EQ(r->stoppage_s, 0.0);
    for (const std::string& m : r->replan_methods)
      EXPECT_THAT(m, ::testing::AnyOf("greedy_detour", "unchanged"));
  }
  // Coverage, against the true map's free area: close to what an offline plan of
  // the true map covers. Calibration: on this office the runs cover 0.882 and
  // the offline plan 0.881 for every method (the robot loses the cells it finds
  // blocked, as the offline plan does; it keeps a few the offline plan cannot
  // reach past thin furniture, which the cell model lets it cross); 3 % leaves
  // room for a different tour, not for a lost room (one room is > 5 %).
  EXPECT_GE(r->covered_free_area_ratio, 0.97 * offline->covered_free_area_ratio);
  EXPECT_LE(r->covered_free_area_ratio, 1.0);
  // Knowing less than the offline plan of the same cell model cannot make the
  // run much shorter (10 % for tour-search noise). Here both offline bounds are
  // close; on maps with chair legs the true map's bound is far higher (barriers).
  EXPECT_GT(r->total_time_s, 0.9 * cell_bound->duration_s);
  EXPECT_LT(r->length_in_obstacles_m, 0.01 * r->path_length_m);
  // The floor of the furnished office: less than the plain office's (the
  // furniture takes some), and the driven path sweeps about as much of it as
  // the offline plan of the true map does.
  std::printf("floor: %.1f m2 reachable, %.4f swept (offline %.4f), %.1f m2 missed\n",
              r->floor.reachable_area_m2, r->floor.swept_reachable_ratio,
              offline->swept_reachable_ratio, r->floor.missed_reachable_m2);
  absl::StatusOr<CoveragePlan> plain = PlanCoverage(known, o.plan);
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_GT(r->floor.reachable_area_m2, 0.5 * plain->stats.reachable_area_m2);
  EXPECT_LT(r->floor.reachable_area_m2, plain->stats.reachable_area_m2);
  EXPECT_GE(r->floor.swept_reachable_ratio, 0.97 * offline->swept_reachable_ratio);
  EXPECT_LE(r->floor.swept_reachable_ratio, 1.0);
  EXPECT_NEAR(r->floor.missed_reachable_m2,
              r->floor.reachable_area_m2 * (1.0 - r->floor.swept_reachable_ratio), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Methods, EveryReplanMethod,
                         ::testing::Values(ReplanMethod::kGreedyDetour, ReplanMethod::kIlp1,
                                           ReplanMethod::kIlp2, ReplanMethod::kAuto,
                                           ReplanMethod::kFull),
                         [](const ::testing::TestParamInfo<ReplanMethod>& info) {
                           return std::string(ReplanMethodName(info.param));
                         });

TEST(Simulate, WithAPerfectMapNothingIsReplannedAndTheRunIsThePlan) {
  const OccupancyMap office = Load("sample_office.yaml");
  SimulationOptions o = Options(ReplanMethod::kAuto);
  o.plan.options = testing::OarpOptionsWith(
      TourSolver::kGreedy);  // deterministic: the plan below is the same one
  absl::StatusOr<SimulationResult> r = Simulate(office, office, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->completed);
  EXPECT_EQ(r->num_replans, 0);
  EXPECT_TRUE(r->obstacles_found.empty());
  EXPECT_EQ(r->stoppage_s, 0.0);
  EXPECT_NEAR(r->total_time_s, r->planned_duration_s, 1e-6 * r->planned_duration_s);
  absl::StatusOr<EngineResult> plan = PlanCoverageWithArea(office, o.plan);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(r->driven.size(), plan->plan.path.size());
  EXPECT_DOUBLE_EQ(r->planned_duration_s, plan->plan.stats.estimated_duration_s);
  EXPECT_NEAR(r->covered_free_area_ratio, plan->plan.stats.covered_free_area_ratio, 1e-9);
  // The floor: the plan's own figures (the same map, the same path).
  EXPECT_GT(r->floor.reachable_area_m2, 0.0);
  EXPECT_NEAR(r->floor.reachable_area_m2, plan->plan.stats.reachable_area_m2, 1e-9);
  EXPECT_NEAR(r->floor.swept_reachable_ratio, plan->plan.stats.swept_reachable_ratio, 1e-9);
  EXPECT_NEAR(r->floor.missed_reachable_m2, plan->plan.stats.missed_reachable_m2, 1e-9);
}

TEST(CellLevelTruth, FillsExactlyTheCellsTheTrueMapBlocks) {
  const OccupancyMap known = Load("sample_office.yaml");
  const OccupancyMap truth = Load("sample_office_furnished.yaml");
  PlanOptions o;
  absl::StatusOr<OccupancyMap> same = CellLevelTruth(known, known, o);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->CountFree(), known.CountFree());
  absl::StatusOr<OccupancyMap> cells = CellLevelTruth(known, truth, o);
  ASSERT_TRUE(cells.ok());
  const Grid k = TrueGrid(known), t = TrueGrid(truth), c = TrueGrid(*cells);
  int64_t filled = 0;
  for (int64_t i = 0; i < k.size(); ++i) {
    const CellIndex cell = k.FromIndex(i);
    EXPECT_EQ(c.IsFree(cell), k.IsFree(cell) && t.IsFree(cell)) << cell.row << "," << cell.col;
    filled += k.IsFree(cell) && !t.IsFree(cell);
  }
  EXPECT_GT(filled, 0);
  OccupancyMap other(known.width() + 1, known.height(), known.resolution(), known.origin());
  EXPECT_EQ(CellLevelTruth(known, other, o).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(Simulate, MapsOfDifferentShapeAreInvalidArgument) {
  const OccupancyMap office = Load("sample_office.yaml");
  const SimulationOptions o = Options(ReplanMethod::kAuto);
  OccupancyMap coarse(office.width(), office.height(), 2 * office.resolution(), office.origin());
  OccupancyMap smaller(office.width() - 1, office.height(), office.resolution(), office.origin());
  OccupancyMap moved(office.width(), office.height(), office.resolution(), {0.5, 0.0});
  for (const OccupancyMap* truth : {&coarse, &smaller, &moved}) {
    absl::StatusOr<SimulationResult> r = Simulate(office, *truth, o);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(r.status().message(), HasSubstr("same size, resolution and origin"));
  }
  SimulationOptions bad = o;
  bad.sensor_range_m = 0.0;
  EXPECT_EQ(Simulate(office, office, bad).status().code(), absl::StatusCode::kInvalidArgument);
}

// Pixels free in `before`, not in `after`.
int64_t NewlyOccupied(const OccupancyMap& before, const OccupancyMap& after) {
  int64_t n = 0;
  for (int r = 0; r < before.height(); ++r) {
    for (int c = 0; c < before.width(); ++c) n += before.IsFree(r, c) && !after.IsFree(r, c);
  }
  return n;
}

// Pixels whose state differs.
int64_t Changed(const OccupancyMap& a, const OccupancyMap& b) {
  int64_t n = 0;
  for (int r = 0; r < a.height(); ++r) {
    for (int c = 0; c < a.width(); ++c) n += a.at(r, c) != b.at(r, c);
  }
  return n;
}

TEST(Clutter, CoversTheRequestedShareOfFreeAreaAndIsReproducible) {
  const OccupancyMap office = Load("sample_office.yaml");
  const double free = static_cast<double>(office.CountFree());
  for (double percent : {0.0, 2.0, 10.0, 20.0, 50.0}) {
    absl::StatusOr<OccupancyMap> a = AddClutter(office, percent, 7);
    ASSERT_TRUE(a.ok()) << a.status();
    const int64_t added = NewlyOccupied(office, *a);
    const double got = 100.0 * added / free;
    EXPECT_NEAR(got, percent, 1.0) << percent;
    EXPECT_GE(got, percent - 0.01) << percent;
    EXPECT_EQ(Changed(office, *a), added) << "only free pixels change, and only to occupied";
    absl::StatusOr<OccupancyMap> again = AddClutter(office, percent, 7);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(Changed(*a, *again), 0) << "same seed, same map";
  }
  absl::StatusOr<OccupancyMap> s1 = AddClutter(office, 10.0, 1);
  absl::StatusOr<OccupancyMap> s2 = AddClutter(office, 10.0, 2);
  ASSERT_TRUE(s1.ok() && s2.ok());
  EXPECT_GT(Changed(*s1, *s2), 0);  // another seed, other rectangles
}

// Free cells of the tool-width grid outside its largest component.
int64_t CutOff(const OccupancyMap& map) {
  const Grid g = TrueGrid(map);
  int64_t best = 0, total = 0;
  std::vector<uint8_t> seen(g.size(), 0);
  for (int64_t i = 0; i < g.size(); ++i) {
    if (!g.IsFree(g.FromIndex(i)) || seen[i]) continue;
    int64_t n = 0;
    std::vector<CellIndex> stack = {g.FromIndex(i)};
    seen[i] = 1;
    while (!stack.empty()) {
      const CellIndex c = stack.back();
      stack.pop_back();
      ++n;
      for (const auto& [dr, dc] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        if (!g.Passable(c.row, c.col, dr, dc) || seen[g.Index(c.row + dr, c.col + dc)]) continue;
        seen[g.Index(c.row + dr, c.col + dc)] = 1;
        stack.push_back({c.row + dr, c.col + dc});
      }
    }
    total += n, best = std::max(best, n);
  }
  return total - best;
}

TEST(Clutter, KeepingTheGridConnectedCutsNoCellOff) {
  const OccupancyMap office = Load("sample_office.yaml");
  ClutterOptions connected;
  connected.keep_connected_cell_m = 0.8;
  int64_t cut_without = 0;
  for (uint64_t seed : {1, 2, 3, 4}) {
    absl::StatusOr<OccupancyMap> a = AddClutter(office, 15.0, seed, connected);
    ASSERT_TRUE(a.ok()) << a.status();
    EXPECT_NEAR(100.0 * NewlyOccupied(office, *a) / office.CountFree(), 15.0, 1.0);
    EXPECT_LE(CutOff(*a), CutOff(office)) << seed;
    absl::StatusOr<OccupancyMap> b = AddClutter(office, 15.0, seed);
    ASSERT_TRUE(b.ok());
    cut_without += CutOff(*b) - CutOff(office);
  }
  EXPECT_GT(cut_without, 0) << "without the rule some rectangle closes a passage";
}

TEST(Clutter, PercentOutsideZeroToFiftyIsInvalidArgument) {
  const OccupancyMap office = Load("sample_office.yaml");
  for (double percent : {-0.1, 50.5, std::nan("")}) {
    EXPECT_EQ(AddClutter(office, percent, 1).status().code(), absl::StatusCode::kInvalidArgument)
        << percent;
  }
}

TEST(Simulate, TenPercentClutterIsDrivenAroundByAuto) {
  const OccupancyMap office = Load("sample_office.yaml");
  absl::StatusOr<OccupancyMap> truth = AddClutter(office, 10.0, 3);
  ASSERT_TRUE(truth.ok());
  SimulationOptions o = Options(ReplanMethod::kAuto);
  o.replan_tour_time_limit_s = 0.25;  // ~50 replans: keep the test quick
  absl::StatusOr<SimulationResult> r = Simulate(office, *truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  std::printf("clutter 10 %%: total %.1f s, stoppage %.2f s, replans %d, coverage %.4f\n",
              r->total_time_s, r->stoppage_s, r->num_replans, r->covered_free_area_ratio);
  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  EXPECT_GT(r->num_replans, 0);
  // Clutter on the start pose is taken off (see the test below).
  EXPECT_EQ(
      FirstBlockedPoint(TrueGrid(r->truth_used != nullptr ? *r->truth_used : *truth), r->driven),
      "");
  EXPECT_NEAR(r->total_time_s, r->drive_time_s + r->stoppage_s, 1e-9 * r->total_time_s);
}

// Clutter dropped onto the parked robot: the true map blocks the cells
// around the plan's start but for a corridor along the robot's row (a ring
// of clutter all round would wall it in: the robot finds the clutter on its
// path and reports those cells). The robot is there, so nothing is: the
// run takes the true map as the known one within a tool width of the start
// (and end) pose, says how many pixels that freed, and drives the rest as
// usual, never entering a cell it reported blocked nor driving through the
// clutter.
TEST(Simulate, ClutterOnTheStartPoseIsTakenOffAndTheRunGoesOn) {
  const OccupancyMap office = Load("sample_office.yaml");
  SimulationOptions o = Options(ReplanMethod::kAuto);
  o.replan_tour_time_limit_s = 0.2;
  absl::StatusOr<CoveragePlan> planned = PlanCoverage(office, o.plan);
  ASSERT_TRUE(planned.ok()) << planned.status();
  const Waypoint start = planned->path.front();
  OccupancyMap truth = office;
  const double res = office.resolution();
  int64_t blocked = 0;
  for (int r = 0; r < office.height(); ++r) {
    for (int c = 0; c < office.width(); ++c) {
      const double x = office.origin().x + (c + 0.5) * res, y = office.origin().y + (r + 0.5) * res;
      if (std::abs(x - start.x) <= 1.0 && std::abs(y - start.y) <= 1.0 &&
          std::abs(y - start.y) > 0.3 && office.IsFree(r, c)) {
        truth.set(r, c, CellState::kOccupied);
        ++blocked;
      }
    }
  }
  ASSERT_GT(blocked, 100);
  absl::StatusOr<SimulationResult> r = Simulate(office, truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_GT(r->truth_cleared_px, 0);
  EXPECT_LT(r->truth_cleared_px, blocked);  // only within a tool width of the poses
  ASSERT_NE(r->truth_used, nullptr);
  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  EXPECT_GT(r->covered_free_area_ratio, 0.8);
  EXPECT_EQ(FirstBlockedPoint(TrueGrid(*r->truth_used), r->driven), "");
  EXPECT_LE(r->length_in_obstacles_m, 0.001 * r->path_length_m);
}

// A number after "key": in the JSON text.
double JsonField(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\": ");
  EXPECT_NE(at, std::string::npos) << key;
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

TEST(SimulateCommand, PrintsEveryFigureAsOneJsonObject) {
  absl::StatusOr<std::string> json =
      SimulateCommandJson({"--map", MapPath("sample_office.yaml"), "--true-map",
                           MapPath("sample_office_furnished.yaml"), "--method", "ilp2", "--local",
                           "--time-limit", "0.5"});
  ASSERT_TRUE(json.ok()) << json.status();
  std::printf("%s\n", json->c_str());
  EXPECT_EQ(json->front(), '{');
  EXPECT_EQ(json->back(), '}');
  EXPECT_THAT(*json, HasSubstr("\"method\": \"ilp2\""));
  EXPECT_THAT(*json, HasSubstr("\"completed\": true"));
  const double total = JsonField(*json, "total_time_s"), drive = JsonField(*json, "drive_time_s");
  const double stoppage = JsonField(*json, "stoppage_s");
  EXPECT_NEAR(total, drive + stoppage, 1e-5);
  EXPECT_GT(JsonField(*json, "num_replans"), 0);
  EXPECT_GE(JsonField(*json, "num_greedy_detours"), 0);
  EXPECT_GT(JsonField(*json, "num_turns"), 0);
  EXPECT_GT(JsonField(*json, "path_length_m"), 0);
  const double coverage = JsonField(*json, "covered_free_area_ratio");
  EXPECT_GT(coverage, 0.5);
  EXPECT_LE(coverage, 1.0);
  EXPECT_GT(JsonField(*json, "offline_lower_bound_s"), 0.5 * total);
  const double floor = JsonField(*json, "swept_reachable_ratio");
  EXPECT_GT(floor, 0.5);
  EXPECT_LE(floor, 1.0);
  EXPECT_GT(JsonField(*json, "reachable_area_m2"), 0.0);
  EXPECT_NEAR(JsonField(*json, "missed_reachable_m2"),
              JsonField(*json, "reachable_area_m2") * (1.0 - floor), 0.01);
  EXPECT_GT(JsonField(*json, "offline_swept_reachable_ratio"), 0.5);
}

TEST(SimulateCommand, BadFlagsAreInvalidArgument) {
  const std::string office = MapPath("sample_office.yaml");
  struct Case {
    std::vector<std::string> args;
    const char* message;
  };
  const std::vector<Case> cases = {
      {{"--map", office, "--clutter", "10", "--server", "127.0.0.1:50051"},
       "not available in this build"},
      {{"--map", office, "--clutter", "10", "--server", "127.0.0.1:50051", "--local"}, "not both"},
      {{"--map", office}, "exactly one of --true-map"},
      {{"--map", office, "--true-map", office, "--clutter", "5"}, "exactly one of --true-map"},
      {{"--map", office, "--clutter", "60"}, "[0, 50]"},
      {{"--map", office, "--clutter", "5", "--method", "fast"}, "--method must be"},
      {{"--true-map", office}, "--map KNOWN is required"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<std::string> r = SimulateCommandJson(c.args);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << c.message;
    EXPECT_THAT(r.status().message(), HasSubstr(c.message));
  }
}

}  // namespace
}  // namespace covplan
