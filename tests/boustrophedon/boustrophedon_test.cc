// Boustrophedon cells partition the free space; each cell's ox-plow path
// sweeps exactly its cells through passable moves; the planner sweeps every
// cell to cover and never leaves a cell half done.
#include <map>
#include <set>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/boustrophedon/boustrophedon_planner.h"
#include "planner/boustrophedon/decomposition.h"
#include "planner/boustrophedon/ox_plow.h"
#include "planner/engine/engine.h"
#include "planner/replan/replanner.h"
#include "tests/testing/grid_fixtures.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

// "" when the decomposition partitions the free cells into cells of one
// linked segment per consecutive column.
std::string CheckPartition(const Grid& g, const BoustrophedonDecomposition& d) {
  std::vector<int> count(static_cast<size_t>(g.size()), 0);
  for (size_t i = 0; i < d.cells.size(); ++i) {
    const BcdCell& cell = d.cells[i];
    if (cell.columns.empty()) return absl::StrFormat("cell %d is empty", i);
    for (size_t k = 0; k < cell.columns.size(); ++k) {
      const int c = cell.first_col + static_cast<int>(k);
      const RowInterval iv = cell.columns[k];
      for (int r = iv.lo; r <= iv.hi; ++r) {
        if (!g.IsFree(r, c)) return absl::StrFormat("cell %d holds blocked (%d, %d)", i, r, c);
        if (r > iv.lo && !g.Passable(r - 1, c, 1, 0))
          return absl::StrFormat("cell %d column %d is not linked", i, c);
        ++count[g.Index(r, c)];
        if (d.cell_of[g.Index(r, c)] != static_cast<int>(i)) return "cell_of disagrees";
      }
      if (k > 0) {
        const RowInterval p = cell.columns[k - 1];
        bool linked = false;
        for (int r = std::max(p.lo, iv.lo); r <= std::min(p.hi, iv.hi); ++r)
          linked |= g.Passable(r, c - 1, 0, 1);
        if (!linked) return absl::StrFormat("cell %d: columns %d and %d not linked", i, c - 1, c);
      }
    }
  }
  for (int64_t i = 0; i < g.size(); ++i) {
    const CellIndex c = g.FromIndex(i);
    if (count[i] != (g.IsFree(c) ? 1 : 0))
      return absl::StrFormat("grid cell (%d, %d) in %d cells", c.row, c.col, count[i]);
  }
  return "";
}

// "" when the element sweeps exactly the cell's cells, each once, and every
// segment moves straight between passable neighbours of the cell.
std::string CheckOxPlow(const Grid& g, const BcdCell& cell, const PolylineElement& e) {
  std::set<std::pair<int, int>> want, got;
  for (size_t k = 0; k < cell.columns.size(); ++k) {
    for (int r = cell.columns[k].lo; r <= cell.columns[k].hi; ++r)
      want.insert({r, cell.first_col + static_cast<int>(k)});
  }
  for (size_t s = 0; s < e.kinds.size(); ++s) {
    const CellIndex a = g.CellAt(e.points[s]), b = g.CellAt(e.points[s + 1]);
    if (a.row != b.row && a.col != b.col) return absl::StrFormat("segment %d is diagonal", s);
    const int dr = (b.row > a.row) - (b.row < a.row), dc = (b.col > a.col) - (b.col < a.col);
    for (CellIndex c = a; c != b; c = {c.row + dr, c.col + dc}) {
      if (!g.Passable(c.row, c.col, dr, dc))
        return absl::StrFormat("segment %d crosses a closed link", s);
      if (!want.count({c.row + dr, c.col + dc}))
        return absl::StrFormat("segment %d leaves the cell", s);
    }
    for (const CellIndex& c : e.sweeps[s]) {
      if (!got.insert({c.row, c.col}).second)
        return absl::StrFormat("(%d, %d) swept twice", c.row, c.col);
    }
    if (e.kinds[s] == SegmentKind::kCoverage &&
        e.sweeps[s].size() !=
            static_cast<size_t>(std::abs(b.row - a.row) + std::abs(b.col - a.col) + 1)) {
      return absl::StrFormat("coverage segment %d does not sweep the cells it drives over", s);
    }
  }
  return got == want ? "" : "the element does not sweep exactly the cell";
}

TEST(Decompose, AnObstacleInTheMiddleSplitsAndMergesTheSlice) {
  const Grid g = Grid::FromAscii({
      "........",
      "........",
      "...##...",
      "...##...",
      "........",
  });
  const BoustrophedonDecomposition d = Decompose(g);
  EXPECT_EQ(CheckPartition(g, d), "");
  // Left of the obstacle, above it, below it, right of it.
  ASSERT_EQ(d.cells.size(), 4u);
  EXPECT_EQ(d.cells[0].first_col, 0);
  EXPECT_EQ(d.cells[0].columns.size(), 3u);
  EXPECT_EQ(d.cells[3].first_col, 5);
  EXPECT_EQ(d.cells[3].NumCells(), 15);
}

TEST(Decompose, ThinWallBarriersSeparateCells) {
  // '|' puts a barrier right of the cell: the two halves touch only through it.
  const Grid g = Grid::FromAscii({
      "..|...",
      "..|...",
      "..|...",
  });
  const BoustrophedonDecomposition d = Decompose(g);
  EXPECT_EQ(CheckPartition(g, d), "");
  EXPECT_EQ(d.cells.size(), 2u);
}

TEST(Decompose, RandomGridsArePartitionedAndEveryCellIsPlowedWhole) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE(seed);
    const Grid g = testing::RandomGrid(14, 17, 0.75, seed);
    const BoustrophedonDecomposition d = Decompose(g);
    ASSERT_EQ(CheckPartition(g, d), "");
    for (size_t i = 0; i < d.cells.size(); ++i) {
      for (auto axis : {std::optional<SweepAxis>(), std::optional(SweepAxis::kVertical),
                        std::optional(SweepAxis::kHorizontal)}) {
        const SweepLines lines = ChooseSweepLines(g, d.cells[i], axis);
        for (bool mirrored : {false, true}) {
          const PolylineElement e = OxPlowElement(g, lines, static_cast<int>(i), mirrored);
          ASSERT_EQ(CheckOxPlow(g, d.cells[i], e), "") << "cell " << i;
          // Plain starts at the first line's first cell, mirrored at its last.
          EXPECT_EQ(e.first_cell, mirrored ? lines.lines[0].back() : lines.lines[0].front());
        }
      }
    }
  }
}

TEST(OxPlow, AWideCorridorIsSweptAlongItsLength) {
  const Grid g = Grid::FromAscii({
      "....................",
      "....................",
      "....................",
  });
  const BoustrophedonDecomposition d = Decompose(g);
  ASSERT_EQ(d.cells.size(), 1u);
  const SweepLines auto_lines = ChooseSweepLines(g, d.cells[0], std::nullopt);
  EXPECT_EQ(auto_lines.axis, SweepAxis::kHorizontal);
  EXPECT_EQ(auto_lines.lines.size(), 3u);
  EXPECT_EQ(ChooseSweepLines(g, d.cells[0], SweepAxis::kVertical).lines.size(), 20u);
  const PolylineElement e = OxPlowElement(g, auto_lines, 0);
  // Three lines, two one-cell moves between them.
  EXPECT_EQ(e.kinds.size(), 5u);
  EXPECT_EQ(CheckOxPlow(g, d.cells[0], e), "");
}

TEST(OxPlow, RowsThatAreNotOneRunFallBackToColumns) {
  // One cell (the slice never changes connectivity), but its top row is
  // interrupted: rows cannot be lines, columns must.
  const Grid g = Grid::FromAscii({
      ".#.",
      "...",
      "...",
  });
  const BoustrophedonDecomposition d = Decompose(g);
  ASSERT_EQ(d.cells.size(), 1u);
  EXPECT_FALSE(BuildSweepLines(g, d.cells[0], SweepAxis::kHorizontal).has_value());
  const SweepLines forced = ChooseSweepLines(g, d.cells[0], SweepAxis::kHorizontal);
  EXPECT_EQ(forced.axis, SweepAxis::kVertical);
  EXPECT_EQ(forced.lines.size(), 3u);
  // Here every row is one run and two rows beat three columns.
  const Grid u = Grid::FromAscii({
      "#.#",
      "...",
  });
  const BoustrophedonDecomposition du = Decompose(u);
  ASSERT_EQ(du.cells.size(), 1u);
  const SweepLines chosen = ChooseSweepLines(u, du.cells[0], std::nullopt);
  EXPECT_EQ(chosen.axis, SweepAxis::kHorizontal);
  EXPECT_EQ(chosen.lines.size(), 2u);
}

MapSource SourceOf(const OccupancyMap& map, const std::string& id) {
  return {id, [&map]() -> absl::StatusOr<SiteMap> {
            SiteMap site;
            site.raster = std::make_shared<const OccupancyMap>(map);
            return site;
          }};
}

TEST(BoustrophedonPlanner, SweepsEveryCellToCoverAndKeepsCellsWhole) {
  const PlannerRegistry registry = BuiltinPlanners();
  for (const std::string name :
       {"small_rooms.yaml", "sample_office.yaml", "sample_office_furnished.yaml"}) {
    SCOPED_TRACE(name);
    const OccupancyMap map = testing::LoadShippedMap(name);
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, EngineLimits{});
    PlanRequest r;
    r.planner = "boustrophedon";
    r.common.robot.tool_width_m = 0.6;
    r.common.time_limit_s = 0.3;
    absl::StatusOr<EngineResult> res = engine.Plan(SourceOf(map, name), r);
    ASSERT_TRUE(res.ok()) << res.status();
    const CoveragePlan& plan = res->plan;
    EXPECT_EQ(testing::CheckPlanConformance(plan, *res->area, r.common.robot, r.no_go), "");
    EXPECT_EQ(plan.stats.covered_cells, plan.stats.free_cells);
    const auto* detail = plan.detail_as<BoustrophedonDetail>();
    ASSERT_NE(detail, nullptr);
    ASSERT_EQ(detail->cell_order.size(), detail->cells.size());
    ASSERT_EQ(detail->cell_mirrored.size(), detail->cells.size());
    EXPECT_EQ(std::set<int>(detail->cell_order.begin(), detail->cell_order.end()).size(),
              detail->cells.size());
    // The coverage segments of a cell form one contiguous run, in tour order.
    std::vector<int> runs;
    for (const Waypoint& w : plan.path) {
      if (w.kind != SegmentKind::kCoverage) continue;
      if (runs.empty() || runs.back() != w.rank) runs.push_back(w.rank);
    }
    EXPECT_EQ(runs, detail->cell_order);
    // Every swept cell lies in the cell of its segment's tag.
    const BoustrophedonDecomposition d = Decompose(*res->area->cover);
    for (const CoverageSweep& s : plan.sweeps) {
      for (const CellIndex& c : s.cells) {
        ASSERT_EQ(d.cell_of[res->area->cover->Index(c.row, c.col)], plan.path[s.waypoint].rank);
      }
    }
  }
}

TEST(BoustrophedonPlanner, PlansCanBeReplannedAroundNewObstacles) {
  const PlannerRegistry registry = BuiltinPlanners();
  const OccupancyMap map = testing::LoadShippedMap("sample_office.yaml");
  LocalArtifactCache cache;
  PlanningEngine engine(&registry, &cache, EngineLimits{});
  PlanRequest r;
  r.planner = "boustrophedon";
  r.common.robot.tool_width_m = 0.8;
  r.common.time_limit_s = 0.3;
  absl::StatusOr<EngineResult> res = engine.Plan(SourceOf(map, "office"), r);
  ASSERT_TRUE(res.ok()) << res.status();
  RetainedPlan retained{"p", "office", res->plan, r, res->area};
  const std::vector<Waypoint>& path = res->plan.path;
  RobotProgress at;
  at.waypoint = static_cast<int>(path.size()) / 5;
  at.position = Point2{path[at.waypoint].x, path[at.waypoint].y};
  // Block a coverage cell well ahead of the robot.
  Observations seen;
  for (size_t i = path.size() / 2; i < path.size(); ++i) {
    if (path[i].kind == SegmentKind::kCoverage) {
      seen.points = {{path[i].x, path[i].y}};
      break;
    }
  }
  ASSERT_FALSE(seen.points.empty());
  absl::StatusOr<ReplanResult> replanned = Replan(retained, at, seen, ReplanOptions(), nullptr);
  ASSERT_TRUE(replanned.ok()) << replanned.status();
  EXPECT_GT(replanned->stats.remaining_cells, 0);
  EXPECT_EQ(replanned->plan.path.front().kind, SegmentKind::kStart);
}

TEST(BoustrophedonPlanner, RefusesForeignOptions) {
  const PlannerRegistry registry = BuiltinPlanners();
  const Planner* p = registry.Find("boustrophedon");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->CheckOptions(OarpOptions()).code(), absl::StatusCode::kInvalidArgument);
  BoustrophedonOptions bad;
  bad.sweep_axis = static_cast<BoustrophedonAxis>(7);
  EXPECT_THAT(std::string(p->CheckOptions(bad).message()),
              ::testing::HasSubstr("boustrophedon.sweep_axis"));
}

}  // namespace
}  // namespace covplan
