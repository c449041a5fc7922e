// The shared plumbing of the element tour models (planner/tour/element_tour.h),
// through the rank model and the polyline model over the same ranks.
#include "planner/tour/element_tour.h"

#include <cmath>
#include <memory>

#include "gtest/gtest.h"
#include "planner/engine/engine.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/tour/path_timing.h"
#include "planner/tour/polyline_tour.h"
#include "planner/tour/rank_tour.h"
#include "tests/testing/grid_fixtures.h"
#include "tests/testing/plan_conformance.h"

namespace covplan {
namespace {

struct Fixture {
  Grid grid = Grid::FromAscii(testing::kRooms, 0.8);
  RankPartition partition = *MinCutPartitioner().Partition(grid, StopToken());
  RobotModel robot;
  Pose2 start{0.5, 0.3, 1.0};
  Fixture() { robot.start = start; }

  PolylineTourModel Polyline() const {
    std::vector<PolylineElement> elements;
    for (size_t k = 0; k < partition.ranks.size(); ++k) {
      const Rank& r = partition.ranks[k];
      elements.push_back(RankElement(grid, r.first, r.last, static_cast<int>(k)));
    }
    return *PolylineTourModel::Create(grid, std::move(elements), start, std::nullopt,
                                      std::make_shared<const TravelTimeCost>(robot), StopToken(),
                                      1);
  }
};

TEST(ElementTour, PolylinePathCostsWhatTheTourCostsAndSweepsEveryRank) {
  const Fixture f;
  const PolylineTourModel model = f.Polyline();
  absl::StatusOr<TourOrder> tour = GtspOrderer({0.3, 1, 1}).Order(model, StopToken());
  ASSERT_TRUE(tour.ok()) << tour.status();
  std::vector<Waypoint> path;
  std::vector<CoverageSweep> sweeps;
  model.BuildPath(tour->vertices, &path, &sweeps);
  EXPECT_NEAR(ComputePathStats(path, f.robot).estimated_duration_s, tour->cost, 1e-6);
  EXPECT_EQ(testing::CheckPathStaysFree(f.grid, path), "");
  ASSERT_EQ(sweeps.size(), f.partition.ranks.size());
  for (size_t i = 0; i < sweeps.size(); ++i) {
    const Waypoint& w = path[sweeps[i].waypoint];
    EXPECT_EQ(w.kind, SegmentKind::kCoverage);
    EXPECT_EQ(static_cast<int>(sweeps[i].cells.size()), f.partition.ranks[w.rank].NumCells());
  }
  EXPECT_NEAR(path.back().x, f.start.x, 1e-9);
  EXPECT_NEAR(path.back().y, f.start.y, 1e-9);
}

// The two models share the plumbing: over the same ranks, moves between
// ranks of two cells or more (whose headings both models derive from the
// rank's axis) cost the same.
TEST(ElementTour, RankAndPolylineModelsPriceTheSameMoves) {
  const Fixture f;
  auto table = TransitionTable::Build(f.grid, f.partition.ranks, StopToken(), 1);
  ASSERT_TRUE(table.ok()) << table.status();
  auto ranks = RankTourCost::Create(f.grid, f.partition.ranks, **table, f.robot, StopToken());
  ASSERT_TRUE(ranks.ok()) << ranks.status();
  const PolylineTourModel polyline = f.Polyline();
  ASSERT_EQ(ranks->num_vertices(), polyline.num_vertices());
  int compared = 0;
  for (int u = 0; u < ranks->num_vertices(); ++u) {
    if (f.partition.ranks[u / 2].NumCells() < 2) continue;
    EXPECT_NEAR(ranks->FromStart(u), polyline.FromStart(u), 1e-9) << u;
    EXPECT_NEAR(ranks->ToEnd(u), polyline.ToEnd(u), 1e-9) << u;
    for (int v = 0; v < ranks->num_vertices(); ++v) {
      if (f.partition.ranks[v / 2].NumCells() < 2) continue;
      if (u / 2 == v / 2) {
        EXPECT_TRUE(std::isinf(ranks->Between(u, v)));
        EXPECT_TRUE(std::isinf(polyline.Between(u, v)));
        continue;
      }
      EXPECT_NEAR(ranks->Between(u, v), polyline.Between(u, v), 1e-9) << u << " -> " << v;
      ++compared;
    }
  }
  EXPECT_GT(compared, 0);
}

TEST(TourPathWriter, SkipsShortTransitsButKeepsDegenerateCoverage) {
  std::vector<Waypoint> path;
  std::vector<CoverageSweep> sweeps;
  TourPathWriter writer(Pose2{0.0, 0.0, 0.5}, &path, &sweeps);
  writer.Transit({{0.0, 0.0}, {0.0, 0.0}, {1.0, 0.0}});
  ASSERT_EQ(path.size(), 2u);  // start, then (1, 0): the repeated point is skipped
  EXPECT_EQ(path[1].kind, SegmentKind::kTransition);
  EXPECT_NEAR(path[1].theta, 0.0, 1e-12);
  writer.Turn(M_PI / 2);
  writer.Segment({1.0, 0.0}, SegmentKind::kCoverage, 7, {CellIndex{0, 1}});
  ASSERT_EQ(path.size(), 3u);  // a zero-length coverage segment stays, on the turned heading
  EXPECT_EQ(path[2].rank, 7);
  EXPECT_NEAR(path[2].theta, M_PI / 2, 1e-12);
  ASSERT_EQ(sweeps.size(), 1u);
  EXPECT_EQ(sweeps[0].waypoint, 2);
  writer.Cover({1.0, 3.0}, -M_PI / 2, 4);  // a rank keeps the heading it is given
  ASSERT_EQ(path.size(), 4u);
  EXPECT_EQ(path[3].kind, SegmentKind::kCoverage);
  EXPECT_NEAR(path[3].theta, -M_PI / 2, 1e-12);
  EXPECT_EQ(sweeps.size(), 1u);
}

}  // namespace
}  // namespace covplan
