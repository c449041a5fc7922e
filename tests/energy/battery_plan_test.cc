// Battery plans through the engine, for every registered planner: each
// charge cycle starts and ends at the station and fits capacity - reserve
// (energy recomputed here from the waypoints), the cycles tile the path, the
// battery plan sweeps exactly what the unconstrained plan sweeps, atomic
// units are never interrupted, and bad battery input is refused with a
// reason naming the field.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/energy/battery.h"
#include "planner/engine/engine.h"
#include "planner/plan/svg.h"
#include "planner/replan/replanner.h"
#include "tests/testing/plan_conformance.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

MapSource SourceOf(const OccupancyMap& map, const std::string& id) {
  return {id, [&map]() -> absl::StatusOr<SiteMap> {
            SiteMap site;
            site.raster = std::make_shared<const OccupancyMap>(map);
            return site;
          }};
}

class BatteryPlans : public ::testing::Test {
 protected:
  BatteryPlans()
      : map_(testing::LoadShippedMap("small_rooms.yaml")),
        engine_(&registry_, &cache_, EngineLimits{}) {}

  PlanRequest Request(const std::string& planner) const {
    PlanRequest r;
    r.planner = planner;
    r.common.robot.tool_width_m = 0.6;
    r.common.time_limit_s = 0.2;
    return r;
  }
  // The centre of a free drive cell near the map's lower left.
  Pose2 FreeStation() {
    absl::StatusOr<std::shared_ptr<const CoverageArea>> area =
        engine_.AreaFor(SourceOf(map_, "m"), Request("oarp"));
    EXPECT_TRUE(area.ok());
    const Grid& g = *(*area)->drive;
    for (int64_t i = 0; i < g.size(); ++i) {
      const CellIndex c = g.FromIndex(i);
      if (g.IsFree(c) && g.IsFree(c.row + 1, c.col) && g.IsFree(c.row, c.col + 1)) {
        const Point2 p = g.CellCenter(c);
        return {p.x, p.y, 0.3};
      }
    }
    return {};
  }
  absl::StatusOr<EngineResult> Plan(const PlanRequest& r) {
    return engine_.Plan(SourceOf(map_, "m"), r);
  }

  OccupancyMap map_;
  PlannerRegistry registry_ = BuiltinPlanners();
  LocalArtifactCache cache_;
  PlanningEngine engine_;
};

// Distance energy of path[lo..hi], independently of planner/energy.
double Distance(const std::vector<Waypoint>& path, int lo, int hi) {
  double d = 0.0;
  for (int i = lo + 1; i <= hi; ++i)
    d += std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  return d;
}

std::set<std::pair<int, int>> Swept(const CoveragePlan& plan) {
  std::set<std::pair<int, int>> out;
  for (const CoverageSweep& s : plan.sweeps) {
    for (const CellIndex& c : s.cells) out.insert({c.row, c.col});
  }
  return out;
}

TEST_F(BatteryPlans, CyclesFitStartAndEndAtTheStationAndCoverWhatThePlanCovers) {
  const Pose2 station = FreeStation();
  for (const std::string& planner : registry_.Names()) {
    const PlanRequest plain = Request(planner);
    absl::StatusOr<EngineResult> unconstrained = Plan(plain);
    ASSERT_TRUE(unconstrained.ok()) << unconstrained.status();
    const double total =
        unconstrained->plan.stats.coverage_length_m + unconstrained->plan.stats.transition_length_m;
    for (double share : {0.5, 0.35}) {
      for (bool interruptible : {false, true}) {
        SCOPED_TRACE(planner + " share " + std::to_string(share) +
                     (interruptible ? " interruptible" : " atomic"));
        PlanRequest r = plain;
        BatteryOptions b;
        b.capacity = total * share + 10.0;
        b.reserve = 5.0;
        b.station = station;
        b.interruptible_units = interruptible;
        r.battery = b;
        absl::StatusOr<EngineResult> res = Plan(r);
        ASSERT_TRUE(res.ok()) << res.status();
        const CoveragePlan& plan = res->plan;
        EXPECT_EQ(testing::CheckPlanConformance(plan, *res->area, r.common.robot, r.no_go), "");
        ASSERT_GE(plan.cycles.size(), 2u);
        EXPECT_EQ(plan.stats.charge_cycles, static_cast<int64_t>(plan.cycles.size()));
        EXPECT_EQ(plan.cycles.front().first_waypoint, 0);
        EXPECT_EQ(plan.cycles.back().last_waypoint, static_cast<int>(plan.path.size()) - 1);
        double sum = 0.0;
        for (size_t c = 0; c < plan.cycles.size(); ++c) {
          const ChargeCycle& cy = plan.cycles[c];
          if (c > 0) {
            EXPECT_EQ(cy.first_waypoint, plan.cycles[c - 1].last_waypoint);
          }
          for (int w : {cy.first_waypoint, cy.last_waypoint}) {
            EXPECT_NEAR(plan.path[w].x, station.x, 1e-9);
            EXPECT_NEAR(plan.path[w].y, station.y, 1e-9);
          }
          const double used = Distance(plan.path, cy.first_waypoint, cy.last_waypoint);
          EXPECT_LE(used, b.capacity - b.reserve + 1e-9);
          EXPECT_NEAR(used, cy.energy, 1e-6);
          EXPECT_LE(cy.first_waypoint, cy.resume_waypoint);
          EXPECT_LT(cy.resume_waypoint, cy.leave_waypoint);
          EXPECT_LT(cy.leave_waypoint, cy.last_waypoint);
          EXPECT_NEAR(cy.energy_at_leave, Distance(plan.path, cy.first_waypoint, cy.leave_waypoint),
                      1e-6);
          // Legs to and from the station, work in between.
          for (int w = cy.first_waypoint + 1; w <= cy.resume_waypoint; ++w) {
            EXPECT_EQ(plan.path[w].kind, SegmentKind::kFromStation);
          }
          for (int w = cy.leave_waypoint + 1; w <= cy.last_waypoint; ++w) {
            EXPECT_EQ(plan.path[w].kind, SegmentKind::kToStation);
          }
          for (int w = cy.resume_waypoint + 1; w <= cy.leave_waypoint; ++w) {
            EXPECT_NE(plan.path[w].kind, SegmentKind::kToStation);
            EXPECT_NE(plan.path[w].kind, SegmentKind::kFromStation);
          }
          sum += cy.energy;
        }
        EXPECT_NEAR(sum, plan.stats.energy_total, 1e-6);
        EXPECT_GE(plan.stats.energy_total + 1e-9, plan.stats.energy_lower_bound);
        EXPECT_EQ(Swept(plan), Swept(unconstrained->plan));
        EXPECT_EQ(plan.stats.covered_cells, unconstrained->plan.stats.covered_cells);
        // Atomic units: every unit's coverage segments lie in one cycle. A
        // unit is a run of coverage segments with one tag in path order (an
        // OARP rank, a boustrophedon cell, one visit of an STC tree node:
        // STC's circumnavigation passes a node more than once).
        if (!interruptible) {
          std::map<int, size_t> cycle_of_unit;  // unit number -> cycle
          int unit = -1, last_tag = -2;
          for (size_t c = 0; c < plan.cycles.size(); ++c) {
            for (int w = plan.cycles[c].resume_waypoint + 1; w <= plan.cycles[c].leave_waypoint;
                 ++w) {
              if (plan.path[w].kind != SegmentKind::kCoverage) continue;
              if (plan.path[w].rank < 0 || plan.path[w].rank != last_tag) ++unit;
              last_tag = plan.path[w].rank;
              auto [it, fresh] = cycle_of_unit.emplace(unit, c);
              EXPECT_EQ(it->second, c) << "unit " << plan.path[w].rank << " interrupted";
            }
            EXPECT_FALSE(plan.cycles[c].resumes_mid_unit);
          }
        }
      }
    }
  }
}

TEST_F(BatteryPlans, InterruptibleCellsResumeWhereTheRobotLeft) {
  const Pose2 station = FreeStation();
  PlanRequest r = Request("boustrophedon");
  absl::StatusOr<EngineResult> plain = Plan(r);
  ASSERT_TRUE(plain.ok());
  BatteryOptions b;
  b.station = station;
  r.battery = b;
  // The least capacity with which atomic cells work (feasibility is monotone).
  double lo = 0.0,
         hi = 2.0 * (plain->plan.stats.coverage_length_m + plain->plan.stats.transition_length_m) +
              50;
  for (int it = 0; it < 14; ++it) {
    r.battery->capacity = 0.5 * (lo + hi);
    (Plan(r).ok() ? hi : lo) = r.battery->capacity;
  }
  // Below it some cell cannot be done in one charge: refused, naming the cell...
  r.battery->capacity = 0.9 * hi;
  const absl::Status atomic = Plan(r).status();
  EXPECT_EQ(atomic.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(atomic.message()), HasSubstr("battery: cell "));
  EXPECT_THAT(std::string(atomic.message()), HasSubstr("needs"));
  // ...unless cells may be interrupted: then some cell is resumed where the
  // robot left it.
  r.battery->interruptible_units = true;
  absl::StatusOr<EngineResult> res = Plan(r);
  ASSERT_TRUE(res.ok()) << res.status();
  int mid = 0;
  for (size_t c = 1; c < res->plan.cycles.size(); ++c) {
    const ChargeCycle& cy = res->plan.cycles[c];
    if (!cy.resumes_mid_unit) continue;
    ++mid;
    const Waypoint& left = res->plan.path[res->plan.cycles[c - 1].leave_waypoint];
    const Waypoint& back = res->plan.path[cy.resume_waypoint];
    EXPECT_NEAR(left.x, back.x, 1e-9);
    EXPECT_NEAR(left.y, back.y, 1e-9);
    EXPECT_EQ(cy.resume_unit, res->plan.path[res->plan.cycles[c - 1].leave_waypoint].rank);
  }
  EXPECT_GT(mid, 0);
  EXPECT_EQ(Swept(res->plan), Swept(plain->plan));
  // A cell listed in atomic_units is never resumed mid-cell (or, if it
  // cannot be done in one charge, the request names it).
  int interrupted = -1;
  for (const ChargeCycle& cy : res->plan.cycles) {
    if (cy.resumes_mid_unit) interrupted = cy.resume_unit;
  }
  r.battery->atomic_units = {interrupted};
  absl::StatusOr<EngineResult> mixed = Plan(r);
  if (mixed.ok()) {
    for (const ChargeCycle& cy : mixed->plan.cycles) {
      EXPECT_FALSE(cy.resumes_mid_unit && cy.resume_unit == interrupted);
    }
    EXPECT_EQ(Swept(mixed->plan), Swept(plain->plan));
  } else {
    EXPECT_THAT(std::string(mixed.status().message()),
                HasSubstr(absl::StrFormat("battery: cell %d needs", interrupted)));
  }
  r.battery->interruptible_units = false;
  EXPECT_THAT(std::string(Plan(r).status().message()), HasSubstr("battery.atomic_units"));
}

TEST_F(BatteryPlans, BadBatteryInputIsRefusedWithAReason) {
  const Pose2 station = FreeStation();
  auto plan_with = [&](BatteryOptions b, const std::string& planner = "oarp") {
    PlanRequest r = Request(planner);
    r.battery = b;
    return Plan(r).status();
  };
  BatteryOptions ok;
  ok.capacity = 1e6;
  ok.station = station;
  ASSERT_TRUE(plan_with(ok).ok()) << plan_with(ok);
  struct Case {
    const char* what;
    BatteryOptions b;
    const char* message;
  };
  std::vector<Case> cases;
  for (double cap : {0.0, -5.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    BatteryOptions b = ok;
    b.capacity = cap;
    cases.push_back({"capacity", b, "battery.capacity"});
  }
  {
    BatteryOptions b = ok;
    b.reserve = b.capacity;
    cases.push_back({"reserve = capacity", b, "battery.reserve"});
    b.reserve = 2 * b.capacity;
    cases.push_back({"reserve > capacity", b, "battery.reserve"});
    b.reserve = -1;
    cases.push_back({"negative reserve", b, "battery.reserve"});
  }
  {
    BatteryOptions b = ok;
    b.station = {-100.0, 3.0, 0.0};
    cases.push_back({"outside", b, "outside the map"});
    b.station = {station.x, std::nan(""), 0.0};
    cases.push_back({"nan station", b, "battery.station"});
  }
  {
    // A pixel deep in an obstacle (all 8 neighbours blocked too).
    BatteryOptions b = ok;
    bool found = false;
    for (int r = 1; r + 1 < map_.height() && !found; ++r) {
      for (int c = 1; c + 1 < map_.width() && !found; ++c) {
        bool all = true;
        for (int dr = -1; dr <= 1; ++dr) {
          for (int dc = -1; dc <= 1; ++dc) all = all && !map_.IsFree(r + dr, c + dc);
        }
        if (!all) continue;
        b.station = {map_.origin().x + (c + 0.5) * map_.resolution(),
                     map_.origin().y + (r + 0.5) * map_.resolution(), 0};
        found = true;
      }
    }
    ASSERT_TRUE(found);
    cases.push_back({"in obstacle", b, "battery.station"});
  }
  {
    BatteryOptions b = ok;
    b.energy.per_metre = -1;
    cases.push_back({"negative energy", b, "battery.energy.per_metre"});
    b.energy.per_metre = 0;
    cases.push_back({"free energy", b, "battery.energy"});
  }
  {
    BatteryOptions b = ok;
    b.capacity = 3.0;  // no rank can be reached and returned from
    cases.push_back({"too small", b, "needs"});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const absl::Status s = plan_with(c.b);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
    EXPECT_THAT(std::string(s.message()), HasSubstr(c.message));
  }
  BatteryOptions tiny = ok;
  tiny.capacity = 3.0;
  EXPECT_THAT(std::string(plan_with(tiny).message()), HasSubstr("battery: rank "));
  EXPECT_THAT(std::string(plan_with(tiny, "boustrophedon").message()), HasSubstr("battery: cell "));
}

TEST_F(BatteryPlans, ReplanningABatteryPlanIsRefusedCleanly) {
  PlanRequest r = Request("oarp");
  BatteryOptions b;
  b.capacity = 100;
  b.station = FreeStation();
  r.battery = b;
  absl::StatusOr<EngineResult> res = Plan(r);
  ASSERT_TRUE(res.ok()) << res.status();
  // Two cycles at least, so a return leg lies ahead of the robot after any
  // detour (with one cycle the tour may reach the station on its own last
  // segment, and a detoured plan without station legs may be replanned).
  ASSERT_GE(res->plan.cycles.size(), 2u);
  RetainedPlan retained{"p", "m", res->plan, r, res->area};
  RobotProgress at;
  at.distance_m = 5.0;
  Observations seen;
  seen.points = {
      {res->plan.path[res->plan.path.size() / 2].x, res->plan.path[res->plan.path.size() / 2].y}};
  absl::StatusOr<ReplanResult> replanned = Replan(retained, at, seen, ReplanOptions(), nullptr);
  EXPECT_EQ(replanned.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(replanned.status().message()), HasSubstr("battery plan"));
  EXPECT_THAT(std::string(replanned.status().message()), HasSubstr("greedy_detour"));

  // The greedy detour drives the old legs around the obstacle, keeping every
  // station visit still ahead (the return legs' kinds, ending at the station).
  ReplanOptions greedy;
  greedy.method = ReplanMethod::kGreedyDetour;
  size_t hit = res->plan.path.size() / 2;
  while (hit + 1 < res->plan.path.size() &&
         (res->plan.path[hit].kind != SegmentKind::kCoverage ||
          std::hypot(res->plan.path[hit].x - b.station.x, res->plan.path[hit].y - b.station.y) <
              2.0)) {
    ++hit;
  }
  seen.points = {
      {res->plan.path[hit].x, res->plan.path[hit].y}};  // a swept cell away from the station
  absl::StatusOr<ReplanResult> detoured = Replan(retained, at, seen, greedy, nullptr);
  ASSERT_TRUE(detoured.ok()) << detoured.status();
  auto station_visits = [&](const std::vector<Waypoint>& path, size_t from) {
    int n = 0;
    for (size_t i = std::max<size_t>(from, 1); i < path.size(); ++i) {
      // Arrivals: a return leg reaching the station (its heading turn after it not counted again).
      const bool at_station = std::hypot(path[i].x - b.station.x, path[i].y - b.station.y) < 1e-9;
      const bool was = std::hypot(path[i - 1].x - b.station.x, path[i - 1].y - b.station.y) < 1e-9;
      n += at_station && !was && path[i].kind == SegmentKind::kToStation;
    }
    return n;
  };
  // The robot is 5 m along the first cycle: every station arrival is ahead of it.
  ASSERT_GT(res->plan.cycles.front().leave_waypoint, 2);
  EXPECT_EQ(station_visits(detoured->plan.path, 1), station_visits(res->plan.path, 1));
  // Every cycle but the last ends on a return leg; the last one may reach
  // the station on the tour's own last segment (when the tour ends there).
  EXPECT_GE(station_visits(res->plan.path, 1), static_cast<int>(res->plan.cycles.size()) - 1);
  EXPECT_LE(station_visits(res->plan.path, 1), static_cast<int>(res->plan.cycles.size()));
  EXPECT_TRUE(detoured->plan.cycles.empty());  // the cycle table is the caller's to recompute
  EXPECT_EQ(detoured->stats.method, "greedy_detour");
  // A replan of the replan is a battery plan too: its station legs survive only the greedy detour.
  RetainedPlan again{"q", "m", detoured->plan, r, detoured->area};
  EXPECT_EQ(Replan(again, at, seen, ReplanOptions(), nullptr).status().code(),
            absl::StatusCode::kFailedPrecondition);
}

TEST_F(BatteryPlans, TheSvgColoursEachCycle) {
  PlanRequest r = Request("oarp");
  BatteryOptions b;
  b.capacity = 60;
  b.station = FreeStation();
  r.battery = b;
  absl::StatusOr<EngineResult> res = Plan(r);
  ASSERT_TRUE(res.ok()) << res.status();
  ASSERT_GE(res->plan.cycles.size(), 2u);
  const std::string svg = RenderPlanSvg(res->plan, &map_);
  EXPECT_THAT(svg, HasSubstr(absl::StrFormat("%d charge cycles", res->plan.cycles.size())));
  EXPECT_THAT(svg, HasSubstr("stroke=\"#e6194b\""));  // cycle 0
  EXPECT_THAT(svg, HasSubstr("stroke=\"#3cb44b\""));  // cycle 1
  absl::StatusOr<EngineResult> plain = Plan(Request("oarp"));
  ASSERT_TRUE(plain.ok());
  EXPECT_THAT(RenderPlanSvg(plain->plan, &map_), ::testing::Not(HasSubstr("charge cycles")));
}

TEST(EnergyModel, TurnsAndTimeAreCharged) {
  RobotModel robot;
  std::vector<Waypoint> path = {{0, 0, 0, SegmentKind::kStart, -1},
                                {2, 0, 0, SegmentKind::kCoverage, 0},
                                {2, 2, M_PI / 2, SegmentKind::kTransition, -1}};
  EnergyModel m;
  EXPECT_DOUBLE_EQ(PathEnergy(path, 0, 2, m, robot), 4.0);
  m.per_turn = 3.0;
  EXPECT_DOUBLE_EQ(PathEnergy(path, 0, 2, m, robot), 7.0);
  m = EnergyModel{0.0, 0.0, 2.0};
  EXPECT_DOUBLE_EQ(PathEnergy(path, 0, 2, m, robot),
                   2.0 * (2 * robot.StraightTime(2.0) + robot.TurnTime(M_PI / 2)));
}

}  // namespace
}  // namespace covplan
