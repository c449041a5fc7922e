// The shared plumbing of the element tour models (planner/tour/element_tour.h),
// through the rank model and the polyline model over the same ranks.
#include "planner/tour/element_tour.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

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

// A move drives the table's path from u's exit to v's entry, or the reverse
// of the path the search from v's entry found back to u's exit when that
// one turns less for the two headings: never slower than either, and on
// grids with obstacles the two differ for some moves.
TEST(ElementTour, MovesTakeTheFasterOfThePathsFoundFromEitherEnd) {
  // The rooms, and pillars (single blocked cells) in three patterns.
  std::vector<Grid> grids = {Grid::FromAscii(testing::kRooms, 0.8)};
  for (int pattern = 0; pattern < 3; ++pattern) {
    std::vector<std::string> rows(13, std::string(15, '.'));
    for (int r = 1; r < 12; r += 3) {
      for (int c = 1 + (r + pattern) % 4; c < 14; c += 4 + pattern) rows[r][c] = '#';
    }
    grids.push_back(Grid::FromAscii(rows, 0.8));
  }
  int reversed = 0;
  for (size_t seed = 0; seed < grids.size(); ++seed) {
    const Grid& grid = grids[seed];
    absl::StatusOr<RankPartition> partition = MinCutPartitioner().Partition(grid, StopToken());
    ASSERT_TRUE(partition.ok()) << partition.status();
    const std::vector<Rank>& ranks = partition->ranks;
    auto table = TransitionTable::Build(grid, ranks, StopToken(), 1);
    ASSERT_TRUE(table.ok()) << table.status();
    RobotModel robot;
    robot.start = Pose2{grid.CellCenter(ranks[0].first).x, grid.CellCenter(ranks[0].first).y, 0};
    auto model = RankTourCost::Create(grid, ranks, **table, robot, StopToken());
    ASSERT_TRUE(model.ok()) << model.status();
    auto time_of = [&](std::vector<CellIndex> cells, bool reverse, double in, double out) {
      if (reverse) std::reverse(cells.begin(), cells.end());
      std::vector<Point2> pts;
      for (const CellIndex& c : cells) pts.push_back(grid.CellCenter(c));
      return TimePolyline(robot, pts, in, out).time_s;
    };
    for (int v = 0; v < model->num_vertices(); ++v) {
      if (ranks[v / 2].NumCells() < 2) continue;
      std::optional<double> traverse;  // Between less the move: the same from every u
      for (int u = 0; u < model->num_vertices(); ++u) {
        if (u / 2 == v / 2 || ranks[u / 2].NumCells() < 2 || !(*table)->Reachable(u ^ 1, v))
          continue;
        std::vector<CellIndex> there, back;
        (*table)->AppendPath(u ^ 1, v, &there);
        (*table)->AppendPath(v, u ^ 1, &back);
        // A rank is left along the heading it is driven (entered) with.
        const double out = model->heading_in(u), in = model->heading_in(v);
        const double forward = time_of(there, false, out, in);
        const double backward = time_of(back, true, out, in);
        reversed += backward < forward - 1e-6;
        const double rest = model->Between(u, v) - std::min(forward, backward);
        if (!traverse) traverse = rest;
        EXPECT_NEAR(rest, *traverse, 1e-6) << "seed " << seed << " " << u << " -> " << v;
      }
    }
  }
  EXPECT_GT(reversed, 0);
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
