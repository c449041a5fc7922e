// libFuzzer target for the map readers (planner/grid/map_io.h).
//
// The first byte selects the reader; the rest is its input:
//   0: DecodeMapImage(rest)            PGM / PNG
//   1: ParseMapYaml(rest)
//   2: DecodeMapYaml(yaml, loader)     rest = yaml '\0' image bytes
//   3: DecodeMapImage(rest) with negate and other thresholds
// Limits are lowered so that a fuzzed header cannot make one input allocate
// hundreds of megabytes; every result must be OK or InvalidArgument.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "planner/grid/map_io.h"

namespace {

void Check(const absl::Status& s) {
  if (!s.ok() && s.code() != absl::StatusCode::kInvalidArgument) {
    std::fprintf(stderr, "unexpected status: %s\n", s.ToString().c_str());
    std::abort();
  }
}

void CheckMap(const absl::StatusOr<covplan::OccupancyMap>& map, const covplan::MapLoadOptions& o) {
  Check(map.status());
  if (!map.ok()) return;
  if (map->width() <= 0 || map->height() <= 0 ||
      static_cast<int64_t>(map->width()) * map->height() > o.max_pixels) {
    std::fprintf(stderr, "bad map size %d x %d\n", map->width(), map->height());
    std::abort();
  }
  volatile int64_t free_cells = map->CountFree();  // touch every cell
  (void)free_cells;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  covplan::MapLoadOptions o;
  o.resolution = 0.05;
  o.max_pixels = 1 << 20;
  o.max_file_bytes = 1 << 20;
  switch (data[0] % 4) {
    case 0:
      CheckMap(covplan::DecodeMapImage(rest, o), o);
      break;
    case 1: {
      absl::StatusOr<covplan::MapYaml> y = covplan::ParseMapYaml(rest, o);
      Check(y.status());
      if (y.ok()) Check(y->options.Validate());
      break;
    }
    case 2: {
      const size_t split = rest.find('\0');
      const std::string_view yaml = rest.substr(0, split);
      const std::string_view image =
          split == std::string_view::npos ? std::string_view() : rest.substr(split + 1);
      auto loader = [image](const std::string&) -> absl::StatusOr<std::string> {
        return std::string(image);
      };
      CheckMap(covplan::DecodeMapYaml(yaml, loader, o), o);
      break;
    }
    case 3:
      o.negate = true;
      o.free_thresh = 0.3;
      o.occupied_thresh = 0.31;
      CheckMap(covplan::DecodeMapImage(rest, o), o);
      break;
  }
  return 0;
}
