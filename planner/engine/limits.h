// The limits of one host (the server's flags, the CLI's defaults) on what a
// request may carry and what planning may cost. One struct for every entry
// point: the api edge reads the input limits (image bytes, map pixels) while
// decoding, the engine and the planners enforce the rest, so the server,
// `covplan plan --local`, the benchmarks and PlanCoverage refuse the same
// requests with the same messages.
//
//   EngineLimits limits;
//   limits.max_grid_cells = 1'000'000;
//   RETURN_IF_ERROR(limits.Validate());
//   PlanningEngine engine(&registry, &cache, limits);
//
// Thread-safety: a plain value.
#ifndef COVPLAN_PLANNER_ENGINE_LIMITS_H_
#define COVPLAN_PLANNER_ENGINE_LIMITS_H_

#include <cstdint>

#include "absl/status/status.h"

namespace covplan {

struct EngineLimits {
  int64_t max_image_bytes = 64ll << 20;  // encoded map image (file or PutMap)
  int64_t max_map_pixels = 64'000'000;   // decoded width * height, polygon rasters too
  int64_t max_grid_cells = 4'000'000;    // tool-width cells
  // OARP: hard cap on coverage ranks. The transitions are bounded by memory
  // (below), not by this count.
  int64_t max_ranks = 100'000;
  // Memory budget of the transitions of one plan (OARP: the exact all-pairs
  // table and dense GTSP, or the sparse candidate graph with its search
  // scratch; boustrophedon: its all-pairs table). Above it: RESOURCE_EXHAUSTED.
  int64_t max_transition_bytes = int64_t{1} << 30;
  // OARP uses the exact all-pairs table and the dense GTSP while they fit in
  // this many bytes (about 100 ranks at the default), the sparse candidate
  // graph and tour search above (planner/tour/sparse_tour.h): on the IPA
  // buildings the sparse tours were within 0.2 % of the dense ones from 80
  // ranks up and 3-8x faster (docs/benchmarks.md §14).
  int64_t dense_transition_bytes = int64_t{4} << 20;
  int64_t max_area_vertices = 100'000;  // per regions / no_go / polygon map
  // Remember plans in the artifact cache (planner/engine/plan_memory.h);
  // false: every request searches from scratch.
  bool plan_memory = true;

  // InvalidArgument unless every size limit is positive (the dense
  // threshold may be 0: always sparse).
  absl::Status Validate() const;
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_LIMITS_H_
