// Battery plans in the simulator (`covplan simulate` drives battery
// plans). With a perfect map the run drives exactly the plan's charge
// cycles: total = drive + recharge x cycles, the energy used is the plan's,
// the battery never goes below the reserve. With clutter the run completes
// around it on the greedy detour, never enters a blocked cell, and its
// battery figures agree with the driven path (recomputed here from the
// waypoints, without planner/energy). Bad battery flags name the flag.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "client/simulate_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/engine/engine.h"
#include "planner/sim/clutter.h"
#include "planner/sim/simulator.h"
#include "planner/tour/path_timing.h"
#include "tests/sim/sim_checks.h"
#include "tests/testing/oarp_options.h"
#include "tests/testing/shipped_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

constexpr double kTool = 0.6;
constexpr char kMap[] = "small_rooms.yaml";

SimulationOptions Options() {
  SimulationOptions o;
  o.plan.robot.tool_width_m = kTool;
  o.plan.time_limit_s = 0.2;
  o.plan.options = testing::OarpOptionsWith(
      TourSolver::kGreedy);  // deterministic: the test plans the same plan again
  return o;
}

// The centre of a free drive cell (with free neighbours above and right).
Pose2 FreeStation(const OccupancyMap& map) {
  absl::StatusOr<EngineResult> plain = PlanCoverageWithArea(map, Options().plan);
  EXPECT_TRUE(plain.ok()) << plain.status();
  if (!plain.ok()) return {};
  const Grid& g = *plain->area->drive;
  for (int64_t i = 0; i < g.size(); ++i) {
    const CellIndex c = g.FromIndex(i);
    if (g.IsFree(c) && g.IsFree(c.row + 1, c.col) && g.IsFree(c.row, c.col + 1)) {
      const Point2 p = g.CellCenter(c);
      return {p.x, p.y, 0.3};
    }
  }
  ADD_FAILURE() << "no free station cell";
  return {};
}

BatteryOptions Battery(const Pose2& station) {
  BatteryOptions b;
  b.capacity = 60;
  b.reserve = 5;
  b.station = station;
  return b;
}

bool AtStation(const Waypoint& w, const Pose2& s) {
  return std::hypot(w.x - s.x, w.y - s.y) <= 1e-6;
}

TEST(BatterySimulation, APerfectMapDrivesExactlyThePlannedCyclesAndRecharges) {
  const OccupancyMap map = testing::LoadShippedMap(kMap);
  SimulationOptions o = Options();
  o.plan.battery = Battery(FreeStation(map));
  o.plan.battery->energy.per_turn =
      0.25;  // turns cost too: the plan's energy model, not just distance
  o.recharge_s = 900.0;
  absl::StatusOr<EngineResult> plan = PlanCoverageWithArea(map, o.plan);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const std::vector<ChargeCycle>& cycles = plan->plan.cycles;
  ASSERT_GE(cycles.size(), 2u);  // a battery that makes the robot go back at least once

  absl::StatusOr<SimulationResult> r = Simulate(map, map, o);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_EQ(r->num_replans, 0);
  EXPECT_THAT(r->problems, ::testing::IsEmpty());
  ASSERT_TRUE(r->battery.has_value());
  const BatteryRun& b = *r->battery;
  ASSERT_EQ(r->driven.size(), plan->plan.path.size());
  EXPECT_EQ(b.charge_cycles_planned, static_cast<int>(cycles.size()));
  EXPECT_EQ(b.charge_cycles_driven, static_cast<int>(cycles.size()));
  ASSERT_EQ(b.cycle_energy.size(), cycles.size());
  for (size_t c = 0; c < cycles.size(); ++c)
    EXPECT_NEAR(b.cycle_energy[c], cycles[c].energy, 1e-9) << c;
  EXPECT_NEAR(b.energy_used, plan->plan.stats.energy_total, 1e-9);
  EXPECT_DOUBLE_EQ(b.energy_planned, plan->plan.stats.energy_total);
  EXPECT_NEAR(r->drive_time_s, plan->plan.stats.estimated_duration_s, 1e-9);
  EXPECT_DOUBLE_EQ(b.recharge_time_s, 900.0 * cycles.size());
  EXPECT_EQ(r->stoppage_s, 0.0);
  EXPECT_NEAR(r->total_time_s, r->drive_time_s + 900.0 * cycles.size(), 1e-9);
  // The fullest cycle leaves the least charge, and it is above the reserve.
  double dearest = 0.0;
  for (const ChargeCycle& c : cycles) dearest = std::max(dearest, c.energy);
  EXPECT_NEAR(b.min_battery_left, o.plan.battery->capacity - dearest, 1e-9);
  EXPECT_GE(b.min_battery_left, o.plan.battery->reserve);
  EXPECT_FALSE(b.below_reserve);
  EXPECT_EQ(b.cycles_over_budget, 0);
  EXPECT_TRUE(b.ended_at_station);
  // Swept free area summed per cell here, per pixel by the engine.
  EXPECT_NEAR(r->covered_free_area_ratio, plan->plan.stats.covered_free_area_ratio, 1e-7);
}

// Clutter over 8 % of the free area (seed 5), none on the station's cell.
void DriveThroughClutter(const Pose2& station, double capacity) {
  const OccupancyMap map = testing::LoadShippedMap(kMap);
  SimulationOptions o = Options();
  o.plan.battery = Battery(station);
  o.plan.battery->capacity = capacity;
  o.recharge_s = 600.0;
  o.method =
      ReplanMethod::kAuto;  // battery plans are replanned by greedy detour whatever this says
  ClutterOptions co;
  co.keep_connected_cell_m = kTool;
  absl::StatusOr<OccupancyMap> cluttered = AddClutter(map, 8.0, 5, co);
  ASSERT_TRUE(cluttered.ok()) << cluttered.status();
  OccupancyMap truth = *cluttered;
  // Nothing on the station's cell (the CLI does the same).
  for (int row = 0; row < map.height(); ++row) {
    for (int col = 0; col < map.width(); ++col) {
      const double x = map.origin().x + (col + 0.5) * map.resolution();
      const double y = map.origin().y + (row + 0.5) * map.resolution();
      if (std::abs(x - station.x) <= kTool && std::abs(y - station.y) <= kTool)
        truth.set(row, col, map.at(row, col));
    }
  }
  absl::StatusOr<EngineResult> plan = PlanCoverageWithArea(map, o.plan);
  ASSERT_TRUE(plan.ok()) << plan.status();

  absl::StatusOr<SimulationResult> r = Simulate(map, truth, o);
  ASSERT_TRUE(r.ok()) << r.status();
  ASSERT_TRUE(r->battery.has_value());
  const BatteryRun& b = *r->battery;
  std::printf(
      "battery + clutter: %d replans, %d cycles driven (%d planned), energy %.2f (planned %.2f), "
      "min left %.2f, over budget %d\n",
      r->num_replans, b.charge_cycles_driven, b.charge_cycles_planned, b.energy_used,
      b.energy_planned, b.min_battery_left, b.cycles_over_budget);
  EXPECT_TRUE(r->completed) << r->termination;
  EXPECT_GT(r->num_replans, 0);
  EXPECT_THAT(r->replan_methods, ::testing::Each(::testing::AnyOf("greedy_detour", "unchanged")));
  EXPECT_EQ(testing::FirstBlockedPoint(testing::TrueGrid(truth, kTool), r->driven), "");
  EXPECT_GT(r->covered_free_area_ratio, 0.8);

  // The battery recomputed from the driven waypoints (energy = distance): a
  // cycle ends where a kToStation segment reaches the station and the robot
  // moves on by another kind of segment (a coverage line or a detour to the
  // station may cross the station's point: that is not docking).
  const std::vector<Waypoint>& d = r->driven;
  ASSERT_TRUE(AtStation(d.front(), station));
  std::vector<double> cycle_length;
  double length = 0.0, current = 0.0;
  bool arrived = false;
  int passes = 0;  // the station's point crossed without docking
  for (size_t i = 1; i < d.size(); ++i) {
    const double step = std::hypot(d[i].x - d[i - 1].x, d[i].y - d[i - 1].y);
    if (arrived && step > 1e-6) {
      if (d[i].kind != SegmentKind::kToStation) {  // docked: it leaves on another kind of leg
        cycle_length.push_back(current);
        current = 0.0;
      }
      arrived = false;
    }
    current += step;
    length += step;
    if (AtStation(d[i], station)) {
      if (d[i].kind == SegmentKind::kToStation) {
        arrived = true;
      } else if (!arrived) {
        ++passes;  // a waypoint of a coverage line or detour at the station's point
      }
    }
  }
  const bool docked = AtStation(d.back(), station);
  if (current > 0.0) cycle_length.push_back(current);
  const int driven_cycles = static_cast<int>(cycle_length.size()) - (docked ? 0 : 1);
  std::printf("station point crossed %d times without docking\n", passes);
  EXPECT_TRUE(docked);  // the plan ends at the station, which the clutter leaves free
  EXPECT_EQ(b.ended_at_station, docked);
  EXPECT_EQ(b.charge_cycles_driven, driven_cycles);
  // The greedy detour keeps every station leg: no charge stop is lost or added.
  EXPECT_EQ(b.charge_cycles_driven, static_cast<int>(plan->plan.cycles.size()));
  ASSERT_EQ(b.cycle_energy.size(), cycle_length.size());
  const double budget = o.plan.battery->budget();
  int over = 0;
  double longest = 0.0;
  for (size_t c = 0; c < cycle_length.size(); ++c) {
    EXPECT_NEAR(b.cycle_energy[c], cycle_length[c], 1e-6) << c;
    over += cycle_length[c] > budget + 1e-6;
    longest = std::max(longest, cycle_length[c]);
  }
  EXPECT_NEAR(b.energy_used, length, 1e-6);
  EXPECT_NEAR(b.energy_used, r->path_length_m, 1e-6);
  EXPECT_EQ(b.cycles_over_budget, over);
  // Every cycle starts full: the lowest charge is at the end of the longest.
  EXPECT_NEAR(b.min_battery_left, o.plan.battery->capacity - longest, 1e-6);
  EXPECT_EQ(b.below_reserve, longest > budget + 1e-6);
  EXPECT_DOUBLE_EQ(b.recharge_time_s, 600.0 * driven_cycles);
  EXPECT_NEAR(r->total_time_s, r->drive_time_s + r->stoppage_s + 600.0 * driven_cycles, 1e-6);
}

TEST(BatterySimulation, ClutterIsDrivenAroundAndTheBatteryFiguresMatchTheDrivenPath) {
  // Tight: the detours may not fit, and that must show.
  DriveThroughClutter(FreeStation(testing::LoadShippedMap(kMap)), 45.0);
}

TEST(BatterySimulation, AStationOnTheCoverageLinesIsPassedWithoutCountingACharge) {
  // (1.5, 1.5) is a cell centre that coverage lines and greedy detours cross.
  DriveThroughClutter({1.5, 1.5, 0.0}, 60.0);
}

TEST(BatterySimulation, AStationTheTrueMapBlocksIsInvalidArgument) {
  const OccupancyMap map = testing::LoadShippedMap(kMap);
  SimulationOptions o = Options();
  const Pose2 station = FreeStation(map);
  o.plan.battery = Battery(station);
  OccupancyMap truth = map;  // a box on the dock
  for (int row = 0; row < map.height(); ++row) {
    for (int col = 0; col < map.width(); ++col) {
      const double x = map.origin().x + (col + 0.5) * map.resolution();
      const double y = map.origin().y + (row + 0.5) * map.resolution();
      if (std::abs(x - station.x) <= kTool / 2 && std::abs(y - station.y) <= kTool / 2) {
        truth.set(row, col, CellState::kOccupied);
      }
    }
  }
  absl::StatusOr<SimulationResult> r = Simulate(map, truth, o);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("battery.station"));
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("free cell of the true map"));
  o.recharge_s = -1;
  EXPECT_THAT(std::string(Simulate(map, map, o).status().message()), HasSubstr("recharge_s"));
}

std::string MapPath(const std::string& name) {
  return std::string(COVPLAN_SOURCE_DIR) + "/maps/" + name;
}

// A number after "key": in the JSON text.
double JsonField(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\": ");
  EXPECT_NE(at, std::string::npos) << key;
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

std::vector<std::string> BatteryArgs(const Pose2& s) {
  return {"--map",
          MapPath(kMap),
          "--true-map",
          MapPath(kMap),
          "--tool-width",
          "0.6",
          "--time-limit",
          "0.2",
          "--battery-capacity",
          "60",
          "--reserve",
          "5",
          "--station",
          absl::StrFormat("%.6f,%.6f", s.x, s.y)};
}

TEST(SimulateCommandBattery, PrintsTheBatteryFigures) {
  std::vector<std::string> args = BatteryArgs(FreeStation(testing::LoadShippedMap(kMap)));
  args.insert(args.end(), {"--recharge-s", "1200"});
  absl::StatusOr<std::string> json = SimulateCommandJson(args);
  ASSERT_TRUE(json.ok()) << json.status();
  std::printf("%s\n", json->c_str());
  EXPECT_THAT(*json, HasSubstr("\"method\": \"greedy_detour\""));
  EXPECT_THAT(*json, HasSubstr("\"below_reserve\": false"));
  EXPECT_THAT(*json, HasSubstr("\"ended_at_station\": true"));
  const double cycles = JsonField(*json, "charge_cycles_driven");
  EXPECT_GE(cycles, 2);
  EXPECT_EQ(cycles, JsonField(*json, "planned_charge_cycles"));
  EXPECT_NEAR(JsonField(*json, "recharge_time_s"), 1200 * cycles, 1e-6);
  EXPECT_NEAR(JsonField(*json, "total_time_s"),
              JsonField(*json, "drive_time_s") + JsonField(*json, "stoppage_s") + 1200 * cycles,
              1e-5);
  EXPECT_NEAR(JsonField(*json, "energy_used"), JsonField(*json, "planned_energy"), 1e-5);
  EXPECT_GE(JsonField(*json, "min_battery_left"), 5.0);
  // The offline bound (a battery plan of the true map) counts its recharges
  // too: every battery plan has at least one cycle, and its drive alone is shorter.
  EXPECT_LT(JsonField(*json, "drive_time_s"), 1200.0);
  EXPECT_GT(JsonField(*json, "offline_lower_bound_s"), 1200.0);
}

TEST(SimulateCommandBattery, BadBatteryFlagsAreInvalidArgumentNamingTheFlag) {
  const Pose2 s = FreeStation(testing::LoadShippedMap(kMap));
  struct Case {
    std::vector<std::string> extra;  // replaces or adds to BatteryArgs
    const char* flag;
  };
  const std::vector<Case> cases = {
      {{"--battery-capacity", "0"}, "--battery-capacity"},
      {{"--battery-capacity", "-3"}, "--battery-capacity"},
      {{"--battery-capacity", "nan"}, "--battery-capacity"},
      {{"--reserve", "60"}, "--reserve"},
      {{"--reserve", "-1"}, "--reserve"},
      {{"--station", "-100,3"}, "--station"},
      {{"--station", "1,x"}, "--station"},
      {{"--station", "1"}, "--station"},
      {{"--energy-per-metre", "-1"}, "--energy-per-metre"},
      {{"--energy-per-metre", "0"}, "--energy-per-*"},
      {{"--recharge-s", "-5"}, "--recharge-s"},
      {{"--method", "ilp2"}, "--method"},
      {{"--atomic-units", "1,2"}, "--atomic-units"},
      {{"--server", "127.0.0.1:50051"}, "--battery-capacity"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = BatteryArgs(s);
    for (size_t i = 0; i + 1 < c.extra.size(); i += 2) {
      auto it = std::find(args.begin(), args.end(), c.extra[i]);
      if (it != args.end()) {
        *(it + 1) = c.extra[i + 1];
      } else {
        args.push_back(c.extra[i]);
        args.push_back(c.extra[i + 1]);
      }
    }
    absl::StatusOr<std::string> r = SimulateCommandJson(args);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument)
        << c.extra[0] << " " << c.extra[1];
    EXPECT_THAT(std::string(r.status().message()), HasSubstr(c.flag)) << r.status();
  }
  // A station without a capacity, and a capacity without a station.
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--map", MapPath(kMap), "--true-map", MapPath(kMap), "--station",
                                 "1,1"},
        std::vector<std::string>{"--map", MapPath(kMap), "--true-map", MapPath(kMap),
                                 "--battery-capacity", "9"}}) {
    absl::StatusOr<std::string> r = SimulateCommandJson(args);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(r.status().message()), HasSubstr("--battery-capacity E and --station"));
  }
}

}  // namespace
}  // namespace covplan
