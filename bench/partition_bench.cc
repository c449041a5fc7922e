// Partition time: min-cut (Boost BK, and push-relabel on the grid),
// bipartite matching (multi-source BFS, Hopcroft-Karp, PF+) and the thesis
// LP (GLPK simplex) on building-like grids and open fields of 10^4, 10^5 and
// 10^6 cells.
//
//   build/bin/partition_bench --benchmark_filter='MinCut|Matching'
//   build/bin/partition_bench --benchmark_filter='Lp/10000'
#include <cmath>
#include <random>
#include <string>

#include "benchmark/benchmark.h"
#include "planner/partition/lp_partitioner.h"
#include "planner/partition/matching_partitioner.h"
#include "planner/partition/mincut_partitioner.h"
#include "planner/partition/push_relabel_partitioner.h"

namespace covplan {
namespace {

// Square-ish grid of `cells` cells: free space with walls every ~12 cells
// (with doors) and random furniture blocks, like a floor plan.
Grid BuildingGrid(int64_t cells, uint32_t seed) {
  const int cols = static_cast<int>(std::sqrt(static_cast<double>(cells)));
  const int rows = static_cast<int>(cells / cols);
  std::vector<uint8_t> free(static_cast<size_t>(rows) * cols, 1);
  std::mt19937 rng(seed);
  auto block = [&](int r0, int c0, int h, int w) {
    for (int r = r0; r < std::min(rows, r0 + h); ++r)
      for (int c = c0; c < std::min(cols, c0 + w); ++c) free[static_cast<size_t>(r) * cols + c] = 0;
  };
  for (int r = 12; r < rows; r += 12 + static_cast<int>(rng() % 5)) {
    block(r, 0, 1, cols);
    // Doors two cells wide.
    for (int c = 3; c + 1 < cols; c += 10 + static_cast<int>(rng() % 6)) {
      free[static_cast<size_t>(r) * cols + c] = 1;
      free[static_cast<size_t>(r) * cols + c + 1] = 1;
    }
  }
  for (int c = 15; c < cols; c += 15 + static_cast<int>(rng() % 7)) {
    for (int r = 0; r < rows; ++r) {
      if (r % 12 > 2) free[static_cast<size_t>(r) * cols + c] = 0;
    }
  }
  const int64_t furniture = cells / 60;
  for (int64_t k = 0; k < furniture; ++k) {
    block(static_cast<int>(rng() % rows), static_cast<int>(rng() % cols), 1 + rng() % 3,
          1 + rng() % 4);
  }
  return Grid(rows, cols, 0.8, {0, 0}, std::move(free));
}

// Times `partitioner` on `grid`; reports the grid's cells, free cells and
// the rank count found.
void TimePartition(benchmark::State& state, const Grid& grid, const RankPartitioner& partitioner) {
  int64_t ranks = 0;
  for (auto _ : state) {
    auto p = partitioner.Partition(grid, StopToken());
    if (!p.ok()) {
      state.SkipWithError(std::string(p.status().message()).c_str());
      break;
    }
    ranks = static_cast<int64_t>(p->ranks.size());
  }
  state.counters["cells"] = static_cast<double>(grid.size());
  state.counters["free_cells"] = static_cast<double>(grid.CountFree());
  state.counters["ranks"] = static_cast<double>(ranks);
}

void BM_MinCut(benchmark::State& state) {
  TimePartition(state, BuildingGrid(state.range(0), 42), MinCutPartitioner(state.range(1) != 0));
}
BENCHMARK(BM_MinCut)
    ->ArgsProduct({{10'000, 100'000, 1'000'000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// An open field (a lawn) of `cells` cells with a scattered 1 % of blocked
// cells (trees, posts).
Grid FieldGrid(int64_t cells, uint32_t seed) {
  const int cols = static_cast<int>(std::sqrt(static_cast<double>(cells)));
  const int rows = static_cast<int>(cells / cols);
  std::vector<uint8_t> free(static_cast<size_t>(rows) * cols, 1);
  std::mt19937 rng(seed);
  for (auto& f : free) f = rng() % 100 != 0;
  return Grid(rows, cols, 0.8, {0, 0}, std::move(free));
}

void BM_MinCutField(benchmark::State& state) {
  TimePartition(state, FieldGrid(state.range(0), 42), MinCutPartitioner(state.range(1) != 0));
}
BENCHMARK(BM_MinCutField)
    ->ArgsProduct({{10'000, 100'000, 1'000'000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// Matching: /0 = multi-source BFS with grafting, /1 = Hopcroft-Karp, /2 =
// multi-source BFS without the greedy initial matching, /3 = Pothen-Fan (PF+).
template <Grid (*MakeGrid)(int64_t, uint32_t)>
void BM_Matching(benchmark::State& state) {
  const int variant = static_cast<int>(state.range(1));
  const MatchingPartitioner partitioner(variant == 1   ? MatchingAlgorithm::kHopcroftKarp
                                        : variant == 3 ? MatchingAlgorithm::kPothenFan
                                                       : MatchingAlgorithm::kMultiSourceBfs,
                                        variant != 2);
  TimePartition(state, MakeGrid(state.range(0), 42), partitioner);
}
BENCHMARK_TEMPLATE(BM_Matching, BuildingGrid)
    ->Name("BM_MatchingBuilding")
    ->ArgsProduct({{10'000, 100'000, 1'000'000}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_TEMPLATE(BM_Matching, FieldGrid)
    ->Name("BM_MatchingField")
    ->ArgsProduct({{10'000, 100'000, 1'000'000}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// The same cut graph as BM_MinCut*, by push-relabel on the implicit grid.
template <Grid (*MakeGrid)(int64_t, uint32_t)>
void BM_PushRelabel(benchmark::State& state) {
  TimePartition(state, MakeGrid(state.range(0), 42), PushRelabelPartitioner());
}
BENCHMARK_TEMPLATE(BM_PushRelabel, BuildingGrid)
    ->Name("BM_PushRelabelBuilding")
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_TEMPLATE(BM_PushRelabel, FieldGrid)
    ->Name("BM_PushRelabelField")
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

void BM_Lp(benchmark::State& state) {
  // GLPK cannot be interrupted: cap at 5 minutes.
  TimePartition(state, BuildingGrid(state.range(0), 42), LpPartitioner(300.0));
}
BENCHMARK(BM_Lp)
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace covplan

BENCHMARK_MAIN();
