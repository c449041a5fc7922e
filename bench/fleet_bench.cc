// Fleet figures on real maps for docs/benchmarks.md: for each map and each
// fleet size k, the makespan division against its lower bound and against
// the equal-area (DARP-style) baseline, on the same maps in one run, with the
// robots starting at k spread-out places (farthest-first over the drive
// grid: the docks at the building's far ends). Each fleet plan is checked:
// every cell to cover swept by some robot, every path segment on free drive
// cells.
//
//   build/bin/fleet_bench --tool 0.8 --budget 1 --robots 2,3,4,8
//       --resolution 0.05 --free-thresh 0.021 MAP.png ...
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <queue>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/engine/engine.h"
#include "planner/fleet/fleet_planner.h"
#include "planner/grid/map_io.h"

namespace covplan {
namespace {

struct Args {
  double tool = 0.8;
  double budget = 1.0;
  double resolution = 0.05;
  double free_thresh = 0.196;
  int threads = 1;
  std::string planner = "oarp";
  std::vector<int> robots = {2, 3, 4, 8};
  std::vector<std::string> maps;
};

// k start poses spread over the drive grid: farthest-first by BFS steps.
std::vector<Pose2> SpreadStarts(const Grid& drive, int k) {
  std::vector<int64_t> seeds;
  std::vector<int> dist(static_cast<size_t>(drive.size()), -1);
  int64_t first = -1;
  for (int64_t i = 0; i < drive.size() && first < 0; ++i)
    if (drive.free_flags()[i]) first = i;
  auto bfs = [&](int64_t from) {
    std::vector<int> d(static_cast<size_t>(drive.size()), -1);
    std::queue<int64_t> q;
    d[from] = 0;
    q.push(from);
    int64_t last = from;
    while (!q.empty()) {
      const int64_t i = q.front();
      q.pop();
      last = i;
      const CellIndex c = drive.FromIndex(i);
      const int dr[4] = {1, -1, 0, 0}, dc[4] = {0, 0, 1, -1};
      for (int m = 0; m < 4; ++m) {
        if (!drive.Passable(c.row, c.col, dr[m], dc[m])) continue;
        const int64_t j = drive.Index(c.row + dr[m], c.col + dc[m]);
        if (d[j] < 0) d[j] = d[i] + 1, q.push(j);
      }
    }
    return std::make_pair(d, last);
  };
  int64_t seed = bfs(first).second;  // one end of the building
  for (int s = 0; s < k; ++s) {
    seeds.push_back(seed);
    const std::vector<int> d = bfs(seed).first;
    int64_t far = seed;
    for (int64_t i = 0; i < drive.size(); ++i) {
      if (d[i] < 0) continue;
      dist[i] = dist[i] < 0 ? d[i] : std::min(dist[i], d[i]);
      if (dist[i] > dist[far]) far = i;
    }
    seed = far;
  }
  std::vector<Pose2> starts;
  for (int64_t s : seeds) {
    const Point2 p = drive.CellCenter(drive.FromIndex(s));
    starts.push_back({p.x, p.y, 0.0});
  }
  return starts;
}

// Empty, or what is wrong: a cell no robot sweeps, a segment off the drive grid.
std::string Check(const FleetPlan& fleet, const CoverageArea& whole) {
  const Grid& drive = *whole.drive;
  std::vector<uint8_t> swept(static_cast<size_t>(drive.size()), 0);
  for (const FleetRobotPlan& rp : fleet.robots) {
    const std::vector<Waypoint>& path = rp.result.plan.path;
    for (const CoverageSweep& s : rp.result.plan.sweeps)
      for (const CellIndex& c : s.cells) swept[drive.Index(c.row, c.col)] = 1;
    for (size_t i = 1; i < path.size(); ++i) {
      const double len = std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
      const int steps = std::max(1, static_cast<int>(len / (0.05 * drive.cell_size())));
      for (int t = 1; t < steps; ++t) {  // the ends may be a dock beside the grid
        const double f = static_cast<double>(t) / steps;
        const Point2 p{path[i - 1].x + f * (path[i].x - path[i - 1].x),
                       path[i - 1].y + f * (path[i].y - path[i - 1].y)};
        if (i > 1 && i + 1 < path.size() && !drive.IsFree(drive.CellAt(p)))
          return absl::StrFormat("%s: segment %d leaves the drive grid", rp.id, i);
      }
    }
  }
  for (int64_t i = 0; i < drive.size(); ++i)
    if (whole.cover->free_flags()[i] && !swept[i]) return "a cell is swept by no robot";
  return "";
}

int Run(const Args& a) {
  const PlannerRegistry registry = BuiltinPlanners();
  std::printf(
      "| map | cells | k | makespan s | mean s | lower bound s | gap | equal-area s | gain | plan "
      "ms | "
      "equal-area ms | closest m | check |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
      "---:|---:|---|\n");
  int failures = 0;
  for (const std::string& path : a.maps) {
    MapLoadOptions lo;
    lo.resolution = a.resolution;
    lo.free_thresh = a.free_thresh;
    absl::StatusOr<OccupancyMap> map = LoadMapFile(path, lo);
    if (!map.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), map.status().ToString().c_str());
      return 2;
    }
    const std::string name = path.substr(path.find_last_of('/') + 1);
    MapSource source{name, [&]() -> absl::StatusOr<SiteMap> {
                       SiteMap site;
                       site.raster = std::make_shared<const OccupancyMap>(*map);
                       return site;
                     }};
    LocalArtifactCache cache;
    EngineLimits limits;
    limits.plan_memory = false;
    PlanningEngine engine(&registry, &cache, limits);
    FleetRequest f;
    f.base.planner = a.planner;
    f.base.common.robot.tool_width_m = a.tool;
    f.base.common.time_limit_s = a.budget;
    f.base.common.num_threads = a.threads;
    absl::StatusOr<std::shared_ptr<const CoverageArea>> whole = engine.AreaFor(source, f.base);
    if (!whole.ok()) return std::fprintf(stderr, "%s\n", whole.status().ToString().c_str()), 2;
    for (int k : a.robots) {
      f.robots.clear();
      const std::vector<Pose2> starts = SpreadStarts(*(*whole)->drive, k);
      for (int r = 0; r < k; ++r) {
        FleetRobot robot;
        robot.id = absl::StrFormat("r%d", r + 1);
        robot.robot.tool_width_m = a.tool;
        robot.robot.start = starts[r];
        robot.robot.end = starts[r];
        f.robots.push_back(robot);
      }
      f.division = FleetDivision::kMakespan;
      absl::StatusOr<FleetPlan> m = PlanFleet(engine, source, f);
      f.division = FleetDivision::kEqualArea;
      absl::StatusOr<FleetPlan> e = PlanFleet(engine, source, f);
      if (!m.ok() || !e.ok()) {
        std::fprintf(stderr, "%s k=%d: %s %s\n", name.c_str(), k, m.status().ToString().c_str(),
                     e.status().ToString().c_str());
        return 2;
      }
      std::string check = Check(*m, **whole);
      if (check.empty()) check = Check(*e, **whole);
      failures += !check.empty();
      std::printf(
          "| %s | %d | %d | %.1f | %.1f | %.1f | %.1f %% | %.1f | %.1f %% | %.0f | %.0f | %.2f | "
          "%s |\n",
          name.c_str(), static_cast<int>((*whole)->cover_cells), k, m->makespan_s,
          m->sum_duration_s / k, m->lower_bound_s, 100.0 * m->gap, e->makespan_s,
          100.0 * (1.0 - m->makespan_s / e->makespan_s), m->planning_ms, e->planning_ms,
          m->safety.closest_approach_m, check.empty() ? "ok" : check.c_str());
      std::fflush(stdout);
    }
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace covplan

int main(int argc, char** argv) {
  covplan::Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (k == "--tool")
      a.tool = std::atof(next().c_str());
    else if (k == "--budget")
      a.budget = std::atof(next().c_str());
    else if (k == "--resolution")
      a.resolution = std::atof(next().c_str());
    else if (k == "--free-thresh")
      a.free_thresh = std::atof(next().c_str());
    else if (k == "--threads")
      a.threads = std::atoi(next().c_str());
    else if (k == "--planner")
      a.planner = next();
    else if (k == "--robots") {
      a.robots.clear();
      for (absl::string_view s : absl::StrSplit(next(), ','))
        a.robots.push_back(std::atoi(std::string(s).c_str()));
    } else
      a.maps.push_back(k);
  }
  if (a.maps.empty()) {
    std::fprintf(stderr, "usage: fleet_bench [--tool M] [--budget S] [--robots 2,3,4,8] MAP...\n");
    return 2;
  }
  return covplan::Run(a);
}
