// The sparse transitions of large maps: candidate lengths are the exact
// any-angle distances, sparse tours are valid plans close to the dense
// solver's, plans above the old 1000-rank limit are not refused, and an
// exceeded transition memory budget is a clear RESOURCE_EXHAUSTED.
#include "planner/tour/sparse_tour.h"

#include <algorithm>
#include <cmath>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/tour/endpoint_graph.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/path_timing.h"
#include "planner/tour/rank_tour.h"
#include "tests/testing/grid_fixtures.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

using testing::kRooms;

std::vector<CellIndex> Endpoints(const std::vector<Rank>& ranks) {
  std::vector<CellIndex> e;
  for (const Rank& r : ranks) {
    e.push_back(r.first);
    e.push_back(r.last);
  }
  return e;
}

bool Connected(const Grid& grid) {
  int32_t comps = 0;
  FreeComponents(grid, &comps);
  return comps == 1;
}

std::vector<Grid> SmallGrids() {
  std::vector<Grid> grids;
  grids.push_back(Grid::FromAscii(kRooms, 0.8));
  for (uint32_t seed = 0; seed < 8; ++seed) {
    Grid g = testing::RandomGrid(14, 18, 0.85, seed);
    if (Connected(g)) grids.push_back(std::move(g));
  }
  return grids;
}

TEST(EndpointGraph, CandidatesAreTheNearestEndpointsAtExactAnyAngleDistances) {
  for (const Grid& grid : SmallGrids()) {
    const RankPartition partition = *MinCutPartitioner().Partition(grid, StopToken());
    const std::vector<CellIndex> endpoints = Endpoints(partition.ranks);
    EndpointGraph::Options options;
    options.neighbours = 4;
    auto graph = EndpointGraph::Build(grid, endpoints, options, StopToken(), 2);
    ASSERT_TRUE(graph.ok()) << graph.status();
    const int count = static_cast<int>(endpoints.size());
    // Full (unbounded) searches from every endpoint: dist[a][b].
    std::vector<std::vector<float>> dist(count, std::vector<float>(count));
    AnyAngleSearch full(grid);
    for (int a = 0; a < count; ++a) {
      ASSERT_TRUE(full.Run(endpoints[a], StopToken()));
      for (int b = 0; b < count; ++b)
        dist[a][b] = static_cast<float>(full.DistanceCells(endpoints[b]));
    }
    for (int e = 0; e < count; ++e) {
      ASSERT_TRUE(full.Run(endpoints[e], StopToken()));
      const auto cands = (*graph)->candidates(e);
      // Every candidate's length is a full search's distance (from e, or
      // from the candidate for entries added by symmetrising: Lazy Theta* is
      // not exactly symmetric), and its path runs from e to the candidate
      // through free cells.
      for (const EndpointCandidate& c : cands) {
        ASSERT_NE(c.endpoint, e);
        ASSERT_NE(c.endpoint, e ^ 1);
        const float forward = dist[e][c.endpoint], backward = dist[c.endpoint][e];
        EXPECT_TRUE(std::abs(c.length_cells - forward) <= 1e-4 ||
                    std::abs(c.length_cells - backward) <= 1e-4)
            << e << "->" << c.endpoint << ": " << c.length_cells << " vs " << forward << " / "
            << backward;
        std::vector<CellIndex> cells;
        (*graph)->AppendPath(e, c, &cells);
        ASSERT_EQ(cells.front(), endpoints[e]);
        ASSERT_EQ(cells.back(), endpoints[c.endpoint]);
        std::vector<Waypoint> wps;
        for (const CellIndex& cell : cells) {
          wps.push_back(
              {grid.CellCenter(cell).x, grid.CellCenter(cell).y, 0, SegmentKind::kTransition, -1});
        }
        EXPECT_EQ(testing::CheckPathStaysFree(grid, wps), "") << e << "->" << c.endpoint;
      }
      // The `neighbours` nearest other endpoints are all in the list: any
      // endpoint nearer than the 4th nearest by more than a cell is a
      // candidate (Lazy Theta* settles cells in tentative-distance order, so
      // near-ties may come in either order).
      std::vector<float> others;
      for (int f = 0; f < count; ++f) {
        if (f != e && f != (e ^ 1)) others.push_back(full.DistanceCells(endpoints[f]));
      }
      std::sort(others.begin(), others.end());
      if (others.size() < 4) continue;
      const float kth = others[3];
      for (int f = 0; f < count; ++f) {
        if (f == e || f == (e ^ 1) || full.DistanceCells(endpoints[f]) >= kth - 1.0f) continue;
        EXPECT_TRUE(std::any_of(cands.begin(), cands.end(),
                                [&](const EndpointCandidate& c) { return c.endpoint == f; }))
            << "endpoint " << f << " is nearer to " << e
            << " than the 4th nearest but no candidate";
      }
      // Lower bounds never exceed the exact distance.
      for (int f = 0; f < count; ++f) {
        EXPECT_LE((*graph)->LowerBoundCells(endpoints[e], endpoints[f]),
                  full.DistanceCells(endpoints[f]) + 1e-4);
      }
    }
  }
}

CoveragePlan SparsePlan(const Grid& grid, const RankPartition& partition, const SparseTour& tour,
                        const RobotModel& robot) {
  CoveragePlan plan;
  plan.grid = std::make_shared<const Grid>(grid);
  auto detail = std::make_shared<OarpDetail>();
  detail->ranks = partition.ranks;
  for (int v : tour.vertices) {
    detail->rank_order.push_back(v / 2);
    detail->rank_reversed.push_back(v % 2 == 1);
  }
  plan.detail = detail;
  plan.path = tour.path;
  plan.stats = ComputePathStats(plan.path, robot);
  plan.stats.num_ranks = static_cast<int64_t>(partition.ranks.size());
  return plan;
}

// Sparse tours drive every rank once, stay in free cells across no barrier,
// honour the poses, and cost at most 10 % more than the dense GTSP's tour on
// the same small grids (the estimated duration of the real paths).
TEST(SparseTour, ValidPlansWithinTenPercentOfTheDenseSolver) {
  constexpr double kFactor = 1.10;
  double sparse_total = 0.0, dense_total = 0.0;
  for (const Grid& grid : SmallGrids()) {
    const RankPartition partition = *MinCutPartitioner().Partition(grid, StopToken());
    auto graph = EndpointGraph::Build(grid, Endpoints(partition.ranks), {}, StopToken(), 2);
    ASSERT_TRUE(graph.ok()) << graph.status();
    for (bool with_end : {false, true}) {
      RobotModel robot;
      const CellIndex s = partition.ranks.back().first;
      robot.start = Pose2{grid.CellCenter(s).x, grid.CellCenter(s).y, 0.3};
      if (with_end) {
        const CellIndex e = partition.ranks.front().last;
        robot.end = Pose2{grid.CellCenter(e).x, grid.CellCenter(e).y, 0.0};
      }
      SparseTourOptions options;
      options.time_limit_s = 5.0;  // converges long before
      options.num_threads = 2;
      auto tour = PlanSparseRankTour(grid, partition.ranks, **graph, robot, options, StopToken());
      ASSERT_TRUE(tour.ok()) << tour.status();
      ASSERT_EQ(tour->vertices.size(), partition.ranks.size());
      const CoveragePlan plan = SparsePlan(grid, partition, *tour, robot);
      EXPECT_EQ(testing::CheckOarpDetail(plan, grid), "");
      EXPECT_EQ(testing::CheckPathStaysFree(grid, plan.path), "");
      const Pose2 end = robot.end.value_or(*robot.start);
      EXPECT_NEAR(plan.path.back().x, end.x, 1e-9);
      EXPECT_NEAR(plan.path.back().y, end.y, 1e-9);
      EXPECT_FALSE(tour->stopped_early);

      auto table = TransitionTable::Build(grid, partition.ranks, StopToken(), 2);
      ASSERT_TRUE(table.ok());
      auto cost = RankTourCost::Create(grid, partition.ranks, **table, robot, StopToken());
      ASSERT_TRUE(cost.ok()) << cost.status();
      auto dense = GtspOrderer({0.5, 1, 1}).Order(*cost, StopToken());
      ASSERT_TRUE(dense.ok());
      EXPECT_LE(plan.stats.estimated_duration_s, kFactor * dense->cost)
          << "sparse " << plan.stats.estimated_duration_s << " s vs dense " << dense->cost << " s";
      sparse_total += plan.stats.estimated_duration_s;
      dense_total += dense->cost;
    }
  }
  RecordProperty("sparse_over_dense", std::to_string(sparse_total / dense_total));
}

// Several threads kick one shared incumbent: with 4 threads the tours are
// valid, the search converges on its shared count of kicks without gain,
// and all grids together cost at most 5 % more than one thread's tours (the
// threads race, so their tours differ from run to run).
TEST(SparseTour, ThreadsShareOneIncumbent) {
  double one_total = 0.0, four_total = 0.0;
  for (const Grid& grid : SmallGrids()) {
    const RankPartition partition = *MinCutPartitioner().Partition(grid, StopToken());
    auto graph = EndpointGraph::Build(grid, Endpoints(partition.ranks), {}, StopToken(), 2);
    ASSERT_TRUE(graph.ok()) << graph.status();
    RobotModel robot;
    const CellIndex s = partition.ranks.front().first;
    robot.start = Pose2{grid.CellCenter(s).x, grid.CellCenter(s).y, 0.0};
    for (int threads : {1, 4}) {
      SparseTourOptions options;
      options.time_limit_s = 10.0;  // converges long before
      options.num_threads = threads;
      auto tour = PlanSparseRankTour(grid, partition.ranks, **graph, robot, options, StopToken());
      ASSERT_TRUE(tour.ok()) << tour.status();
      ASSERT_EQ(tour->vertices.size(), partition.ranks.size());
      EXPECT_FALSE(tour->stopped_early) << threads << " threads";
      EXPECT_EQ(tour->termination.reason, TerminationReason::kConverged);
      EXPECT_EQ(tour->termination.detail, "sparse tour search converged");
      const CoveragePlan plan = SparsePlan(grid, partition, *tour, robot);
      EXPECT_EQ(testing::CheckOarpDetail(plan, grid), "");
      EXPECT_EQ(testing::CheckPathStaysFree(grid, plan.path), "");
      (threads == 1 ? one_total : four_total) += plan.stats.estimated_duration_s;
    }
  }
  EXPECT_LE(four_total, 1.05 * one_total)
      << "4 threads " << four_total << " s vs 1 thread " << one_total << " s";
}

// A warm start from a cold search's own tour, from another start pose:
// every rank once in a valid plan that starts and ends where asked, at most
// 10 % above the cold search from the same pose. A tour that repeats a rank
// is ignored (a cold search runs).
TEST(SparseTour, WarmStartFromARememberedTour) {
  for (const Grid& grid : SmallGrids()) {
    const RankPartition partition = *MinCutPartitioner().Partition(grid, StopToken());
    auto graph = EndpointGraph::Build(grid, Endpoints(partition.ranks), {}, StopToken(), 2);
    ASSERT_TRUE(graph.ok()) << graph.status();
    RobotModel robot;
    const CellIndex s = partition.ranks.back().first;
    robot.start = Pose2{grid.CellCenter(s).x, grid.CellCenter(s).y, 0.3};
    SparseTourOptions options;
    options.time_limit_s = 5.0;
    auto remembered =
        PlanSparseRankTour(grid, partition.ranks, **graph, robot, options, StopToken());
    ASSERT_TRUE(remembered.ok()) << remembered.status();
    EXPECT_FALSE(remembered->warm_started);

    RobotModel moved = robot;
    const CellIndex m = partition.ranks.front().last;
    moved.start = Pose2{grid.CellCenter(m).x, grid.CellCenter(m).y, 1.0};
    auto cold = PlanSparseRankTour(grid, partition.ranks, **graph, moved, options, StopToken());
    ASSERT_TRUE(cold.ok()) << cold.status();
    SparseTourOptions warm_options = options;
    warm_options.warm_vertices = remembered->vertices;
    warm_options.warm_kicks = false;
    auto warm =
        PlanSparseRankTour(grid, partition.ranks, **graph, moved, warm_options, StopToken());
    ASSERT_TRUE(warm.ok()) << warm.status();
    EXPECT_TRUE(warm->warm_started);
    ASSERT_EQ(warm->vertices.size(), partition.ranks.size());
    const CoveragePlan plan = SparsePlan(grid, partition, *warm, moved);
    EXPECT_EQ(testing::CheckOarpDetail(plan, grid), "");
    EXPECT_EQ(testing::CheckPathStaysFree(grid, plan.path), "");
    EXPECT_NEAR(plan.path.front().x, moved.start->x, 1e-9);
    EXPECT_NEAR(plan.path.back().x, moved.start->x, 1e-9);  // no end: back to the start
    EXPECT_NEAR(plan.path.back().y, moved.start->y, 1e-9);
    EXPECT_LE(warm->surrogate_cost, 1.10 * cold->surrogate_cost)
        << "warm " << warm->surrogate_cost << " s vs cold " << cold->surrogate_cost << " s";

    if (partition.ranks.size() >= 2) {
      SparseTourOptions bad = warm_options;
      bad.warm_vertices[1] = bad.warm_vertices[0];  // rank twice, another never
      auto fallback = PlanSparseRankTour(grid, partition.ranks, **graph, moved, bad, StopToken());
      ASSERT_TRUE(fallback.ok()) << fallback.status();
      EXPECT_FALSE(fallback->warm_started);
      EXPECT_EQ(fallback->vertices.size(), partition.ranks.size());
    }
  }
}

// A comb of thin walls: `teeth` one-cell gaps below a two-row corridor, one
// rank per gap plus the corridor's (1 px = one 0.1 m cell).
OccupancyMap Comb(int teeth) {
  const int width = 2 * teeth + 1, height = 12;
  OccupancyMap map(width, height, 0.1, {0.0, 0.0});
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const bool wall = (c % 2 == 1) && r < height - 2;
      map.set(r, c, wall ? CellState::kOccupied : CellState::kFree);
    }
  }
  return map;
}

PlanOptions CombOptions() {
  PlanOptions o;
  o.robot.tool_width_m = 0.1;
  o.time_limit_s = 1.0;
  o.num_threads = 2;
  return o;
}

TEST(SparseTour, PlanAboveTheOldThousandRankLimitIsNotRefused) {
  const OccupancyMap map = Comb(1250);
  const PlanOptions o = CombOptions();
  absl::StatusOr<EngineResult> r = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_GT(r->plan.stats.num_ranks, 1200);
  EXPECT_EQ(r->plan.stats.tour_solver, "sparse");
  EXPECT_EQ(testing::CheckOarpConformance(*r, o.robot), "");
}

TEST(SparseTour, ExceededTransitionBudgetIsResourceExhaustedNamingTheBudget) {
  const OccupancyMap map = Comb(1250);
  EngineLimits limits;
  limits.max_transition_bytes = int64_t{1} << 20;
  absl::StatusOr<EngineResult> r =
      PlanCoverageWithArea(map, CombOptions(), nullptr, "local", limits);
  ASSERT_EQ(r.status().code(), absl::StatusCode::kResourceExhausted) << r.status();
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("transition memory budget of 1 MiB"));
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("--max_transition_mb"));
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("coverage ranks"));
}

TEST(SparseTour, DenseBelowTheDenseBudgetSparseAbove) {
  const OccupancyMap map = testing::LoadShippedMap("small_rooms.yaml");
  PlanOptions o;
  o.robot.tool_width_m = 0.5;
  o.time_limit_s = 0.3;
  absl::StatusOr<EngineResult> dense = PlanCoverageWithArea(map, o);
  ASSERT_TRUE(dense.ok()) << dense.status();
  EXPECT_EQ(dense->plan.stats.tour_solver, "gtsp");
  EngineLimits limits;
  limits.dense_transition_bytes = 0;
  absl::StatusOr<EngineResult> sparse = PlanCoverageWithArea(map, o, nullptr, "local", limits);
  ASSERT_TRUE(sparse.ok()) << sparse.status();
  EXPECT_EQ(sparse->plan.stats.tour_solver, "sparse");
  EXPECT_EQ(testing::CheckOarpConformance(*sparse, o.robot), "");
  EXPECT_EQ(sparse->plan.stats.num_ranks, dense->plan.stats.num_ranks);
}

}  // namespace
}  // namespace covplan
