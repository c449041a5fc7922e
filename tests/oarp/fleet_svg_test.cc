// RenderFleetSvg (planner/plan/fleet_svg.h): several plans on one grid in one
// picture, each robot in its own colour with its start marked, its share
// tinted and a legend entry with its id and duration.
#include "planner/plan/fleet_svg.h"

#include <memory>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/grid/grid.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Sweeps row `row` of `grid` from column 0 to its last column, after
// driving there from (x, y).
CoveragePlan RowPlan(std::shared_ptr<const Grid> grid, int row, Point2 from) {
  CoveragePlan plan;
  plan.grid = grid;
  const Point2 a = grid->CellCenter(row, 0), b = grid->CellCenter(row, grid->cols() - 1);
  plan.path.push_back({from.x, from.y, 0.0, SegmentKind::kStart, -1});
  plan.path.push_back({a.x, a.y, 0.0, SegmentKind::kTransition, -1});
  plan.path.push_back({b.x, b.y, 0.0, SegmentKind::kCoverage, 0});
  plan.path.push_back({from.x, from.y, 0.0, SegmentKind::kTransition, -1});
  CoverageSweep sweep;
  sweep.waypoint = 2;
  for (int c = 0; c < grid->cols(); ++c) sweep.cells.push_back({row, c});
  plan.sweeps.push_back(sweep);
  return plan;
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(FleetSvg, EachRobotGetsItsColourStartAndLegendEntry) {
  auto grid = std::make_shared<const Grid>(Grid::FromAscii({"......", "......", "......"}, 0.5));
  const CoveragePlan a = RowPlan(grid, 0, grid->CellCenter(1, 0));
  const CoveragePlan b = RowPlan(grid, 2, grid->CellCenter(1, 5));
  const std::string svg = RenderFleetSvg({{"alpha", &a, 12.25}, {"beta", &b, 9.5}}, *grid, nullptr,
                                         {}, "makespan 12 s");
  EXPECT_THAT(svg, HasSubstr("<svg"));
  EXPECT_THAT(svg, HasSubstr("</svg>\n"));
  EXPECT_EQ(Count(svg, "<g "), Count(svg, "</g>"));
  const std::string ca = FleetSvgColour(0), cb = FleetSvgColour(1);
  EXPECT_NE(ca, cb);
  // Coverage, transitions, start disc (outlined) and end ring in each colour.
  for (const std::string& c : {ca, cb}) {
    SCOPED_TRACE(c);
    EXPECT_THAT(svg, HasSubstr("stroke=\"" + c + "\" stroke-width"));
    EXPECT_THAT(svg, HasSubstr("fill=\"" + c + "\" stroke=\"#000000\""));
    EXPECT_THAT(svg, HasSubstr("fill=\"none\" stroke=\"" + c + "\""));
    EXPECT_THAT(svg, HasSubstr("<g fill=\"" + c + "\" shape-rendering"));  // its share
  }
  // The start discs sit at the plans' first waypoints.
  const Point2 sa = grid->CellCenter(1, 0);
  EXPECT_THAT(svg, HasSubstr(absl::StrFormat("<circle cx=\"%.4f\" cy=\"%.4f\"", sa.x, sa.y)));
  // The legend: title, ids in their colours, durations.
  EXPECT_THAT(svg, HasSubstr("makespan 12 s"));
  EXPECT_THAT(svg, HasSubstr("fill=\"" + ca + "\" font-weight=\"bold\">alpha</tspan> 12 s"));
  EXPECT_THAT(svg, HasSubstr("fill=\"" + cb + "\" font-weight=\"bold\">beta</tspan> 10 s"));
  // No single-plan colouring by sweep direction.
  EXPECT_THAT(svg, Not(HasSubstr("#f08c2e")));
}

TEST(FleetSvg, ColoursCycleAfterEightAndIdsAreEscaped) {
  std::set<std::string> colours;
  for (size_t i = 0; i < kFleetSvgColours; ++i) colours.insert(FleetSvgColour(i));
  EXPECT_EQ(colours.size(), kFleetSvgColours);
  EXPECT_EQ(std::string(FleetSvgColour(kFleetSvgColours)), FleetSvgColour(0));
  EXPECT_EQ(std::string(FleetSvgColour(kFleetSvgColours + 3)), FleetSvgColour(3));

  auto grid = std::make_shared<const Grid>(Grid::FromAscii({"....", "...."}));
  const CoveragePlan a = RowPlan(grid, 0, grid->CellCenter(0, 0));
  CoveragePlan idle;  // a robot given nothing: its start only
  idle.grid = grid;
  idle.path.push_back({3.5, 1.5, 0.0, SegmentKind::kStart, -1});
  std::vector<FleetSvgRobot> robots;
  for (int i = 0; i < 10; ++i) robots.push_back({absl::StrCat("r", i), i == 9 ? &idle : &a, 1.0});
  robots[1].id = "<b&\"x\">";
  robots[2].plan = nullptr;  // drawn in the legend only
  const std::string svg = RenderFleetSvg(robots, *grid, nullptr);
  EXPECT_THAT(svg, HasSubstr("&lt;b&amp;&quot;x&quot;&gt;"));
  EXPECT_THAT(svg, Not(HasSubstr("<b&")));
  // Ten robots: the key row, then several robots per row.
  EXPECT_GE(Count(svg, "<text "), 2u);
  EXPECT_LE(Count(svg, "<text "), 4u);
  for (int i = 3; i < 10; ++i) EXPECT_THAT(svg, HasSubstr(absl::StrCat(">r", i, "</tspan>")));
  EXPECT_EQ(Count(svg, "<g "), Count(svg, "</g>"));
}

}  // namespace
}  // namespace covplan
