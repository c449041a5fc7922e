// Plans real maps and prints markdown tables for docs/benchmarks.md:
//  1. partition: grid size, optimal rank count, min-cut vs LP time, covered
//     free-area ratio;
//  2. plans: greedy vs GTSP tours (turns, lengths, duration, time split),
//     median of --runs runs, and the gap to a long (--reference-s) search.
//
//   build/bin/map_bench --resolution 0.05 --free-thresh 0.021 MAP.png ...
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <fstream>
#include "absl/strings/str_format.h"
#include "planner/assembly/plan_coverage.h"
#include "planner/grid/map_io.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/plan/svg.h"

namespace covplan {
namespace {

struct Args {
  double resolution = 0.05;
  double free_thresh = 0.196;
  double tool_width = 0.8;
  double time_limit = 0.5;
  double reference_s = 30.0;
  int runs = 5;
  int threads = 2;
  bool lp = true;
  GtspEffort effort = GtspEffort::kDefault;
  std::string svg_dir;  // write <map>.svg of the GTSP plan here
  std::vector<std::string> maps;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// OARP's options for one run (PlanOptions::options).
std::shared_ptr<const OarpOptions> OarpWith(TourSolver tour, GtspEffort effort) {
  auto options = std::make_shared<OarpOptions>();
  options->tour_solver = tour;
  options->tour_effort = effort;
  return options;
}

std::string Base(const std::string& p) {
  std::string b = p.substr(p.find_last_of('/') + 1);
  return b.substr(0, b.find_last_of('.'));
}

int Run(const Args& a) {
  std::string partition_table =
      "| map | grid (rows x cols) | free cells | unreachable cells | ranks (min-cut) | ranks (LP) "
      "| "
      "ranks without thin-wall barriers | min-cut ms | LP ms | covered free-area ratio |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n";
  std::string plan_table =
      "| map | tour | ranks | turns | coverage m | transition m | duration s | grid ms | partition "
      "ms | "
      "transitions ms | tour ms | total ms (median) | gap to long search |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const std::string& path : a.maps) {
    MapLoadOptions lo;
    lo.resolution = a.resolution;
    lo.free_thresh = a.free_thresh;
    absl::StatusOr<OccupancyMap> map = LoadMapFile(path, lo);
    if (!map.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), std::string(map.status().message()).c_str());
      return 1;
    }
    PlanOptions po;
    po.robot.tool_width_m = a.tool_width;
    po.num_threads = a.threads;
    // The per-map artifacts once (kept for the reference search below).
    LocalArtifactCache cache;
    PlanOptions warm = po;
    warm.options = OarpWith(TourSolver::kGreedy, GtspEffort::kDefault);
    auto d = PlanCoverageWithArea(*map, warm, &cache, path);
    if (!d.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), std::string(d.status().message()).c_str());
      return 1;
    }
    const CoverageArea& area = *d->area;
    const Grid& grid = *area.cover;
    // Partition timings on the planned grid, median of runs.
    std::vector<double> cut_ms, lp_ms;
    size_t cut_ranks = 0, lp_ranks = 0;
    for (int r = 0; r < a.runs; ++r) {
      absl::Time t = absl::Now();
      auto p = MinCutPartitioner().Partition(grid, StopToken());
      cut_ms.push_back(absl::ToDoubleMilliseconds(absl::Now() - t));
      cut_ranks = p->ranks.size();
      if (a.lp && r < 2) {
        t = absl::Now();
        auto q = LpPartitioner(300).Partition(grid, StopToken());
        lp_ms.push_back(absl::ToDoubleMilliseconds(absl::Now() - t));
        lp_ranks = q.ok() ? q->ranks.size() : 0;
      }
    }
    // Thesis-style grid (no barriers, all components) for comparison.
    GridOptions plain;
    plain.cell_size = po.robot.tool_width_m;
    plain.min_free_fraction = po.min_free_fraction;
    plain.thin_wall_barriers = false;
    auto plain_grid = BuildGrid(*map, plain);
    const size_t plain_ranks =
        MinCutPartitioner().Partition(*plain_grid, StopToken())->ranks.size();
    absl::StrAppendFormat(
        &partition_table, "| %s | %d x %d | %d | %d | %d | %s | %d | %.2f | %s | %.4f |\n",
        Base(path), grid.rows(), grid.cols(), grid.CountFree(), area.unreachable_cells, cut_ranks,
        a.lp ? absl::StrCat(lp_ranks) : "-", plain_ranks, Median(cut_ms),
        a.lp ? absl::StrFormat("%.1f", Median(lp_ms)) : "-", area.covered_free_area_ratio);
    std::fflush(stdout);
    // Long reference search for the tour gap.
    double reference = 0.0;
    if (a.reference_s > 0) {
      PlanOptions ro = po;
      ro.time_limit_s = a.reference_s;
      ro.options = OarpWith(TourSolver::kGtsp, GtspEffort::kThorough);
      auto ref = PlanCoverage(*map, ro, &cache, path);
      if (ref.ok()) reference = ref->stats.estimated_duration_s;
    }
    for (TourSolver ts : {TourSolver::kGreedy, TourSolver::kGtsp}) {
      std::vector<double> total;
      absl::StatusOr<CoveragePlan> last = absl::UnknownError("no run");
      for (int r = 0; r < a.runs; ++r) {
        PlanOptions o = po;
        o.options = OarpWith(ts, a.effort);
        o.time_limit_s = a.time_limit;
        o.seed = 1 + r;
        // Full pipeline from the map, as a fresh request would run it.
        last = PlanCoverage(*map, o);
        if (!last.ok()) break;
        total.push_back(last->stats.planning_ms);
      }
      if (!last.ok()) {
        std::fprintf(stderr, "%s: %s\n", path.c_str(),
                     std::string(last.status().message()).c_str());
        return 1;
      }
      if (!a.svg_dir.empty() && ts == TourSolver::kGtsp) {
        std::ofstream(a.svg_dir + "/" + Base(path) + ".svg") << RenderPlanSvg(*last, &*map);
      }
      const PlanStats& s = last->stats;
      const std::string gap =
          reference > 0 ? absl::StrFormat("%+.2f %%",
                                          100.0 * (s.estimated_duration_s - reference) / reference)
                        : "-";
      absl::StrAppendFormat(
          &plan_table,
          "| %s | %s | %d | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %s |\n",
          Base(path), s.tour_solver, s.num_ranks, s.num_turns, s.coverage_length_m,
          s.transition_length_m, s.estimated_duration_s, s.grid_ms, s.partition_ms,
          s.transitions_ms, s.tour_ms, Median(total), gap);
    }
    std::fprintf(stderr, "done %s\n", path.c_str());
  }
  std::printf("### Partition\n\n%s\n### Plans\n\n%s", partition_table.c_str(), plan_table.c_str());
  return 0;
}

}  // namespace
}  // namespace covplan

int main(int argc, char** argv) {
  covplan::Args a;
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "missing value for %s\n", k.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (k == "--resolution")
      a.resolution = std::atof(next().c_str());
    else if (k == "--free-thresh")
      a.free_thresh = std::atof(next().c_str());
    else if (k == "--tool-width")
      a.tool_width = std::atof(next().c_str());
    else if (k == "--time-limit")
      a.time_limit = std::atof(next().c_str());
    else if (k == "--reference-s")
      a.reference_s = std::atof(next().c_str());
    else if (k == "--runs")
      a.runs = std::atoi(next().c_str());
    else if (k == "--threads")
      a.threads = std::atoi(next().c_str());
    else if (k == "--no-lp")
      a.lp = false;
    else if (k == "--effort") {
      const std::string e = next();
      a.effort = e == "fast"       ? covplan::GtspEffort::kFast
                 : e == "thorough" ? covplan::GtspEffort::kThorough
                                   : covplan::GtspEffort::kDefault;
    } else if (k == "--svg-dir")
      a.svg_dir = next();
    else if (k.rfind("--", 0) == 0) {
      std::fprintf(stderr, "unknown flag %s\n", k.c_str());
      return 2;
    } else
      a.maps.push_back(k);
  }
  if (a.maps.empty()) {
    std::fprintf(stderr, "usage: map_bench [flags] MAP...\n");
    return 2;
  }
  return covplan::Run(a);
}
