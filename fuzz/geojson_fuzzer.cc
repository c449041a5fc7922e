// libFuzzer target for the GeoJSON reader (api/geojson.h) and the polygon geometry behind it
// (planner/geometry/area.h).
//
// The input is a GeoJSON document. Whatever it holds, ParseGeoJsonPolygons and Area::Create
// must return OK or InvalidArgument; an accepted area must then give cell fractions in [0, 1]
// that add up to its area, and images whose kInside pixels are a subset of the kCentre ones.
// Limits are lowered so that one input cannot take seconds.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "api/geojson.h"
#include "planner/geometry/area.h"

namespace {

void Check(const absl::Status& s, const char* what) {
  if (!s.ok() && s.code() != absl::StatusCode::kInvalidArgument) {
    std::fprintf(stderr, "%s: unexpected status: %s\n", what, s.ToString().c_str());
    std::abort();
  }
}

[[noreturn]] void Fail(const char* what, double value) {
  std::fprintf(stderr, "%s (%.17g)\n", what, value);
  std::abort();
}

void CheckArea(const covplan::Area& area) {
  const double a = area.AreaM2();
  if (!(a > 0)) Fail("non-empty area with non-positive area", a);
  const covplan::Point2 lo = area.min_corner(), hi = area.max_corner();
  const double extent = std::max(hi.x - lo.x, hi.y - lo.y);
  if (!std::isfinite(a) || !std::isfinite(extent) || !(extent > 0)) return;  // beyond doubles

  constexpr int kCells = 16;
  const double cell = extent / (kCells - 2);
  const covplan::Point2 origin{lo.x - cell, lo.y - cell};
  const std::vector<float> f = covplan::CellOverlapFractions(area, kCells, kCells, cell, origin);
  if (f.size() != kCells * kCells) Fail("wrong number of fractions", f.size());
  double sum = 0.0;
  for (float v : f) {
    if (!(v >= 0.0f && v <= 1.0f)) Fail("fraction outside [0, 1]", v);
    sum += v;
  }
  const double cell_area = cell * cell;
  if (std::isnormal(cell_area) && a / cell_area > 1e-3) {
    const double covered = sum * cell_area;
    if (std::abs(covered - a) > 1e-3 * a + 1e-5 * kCells * kCells * cell_area) {
      std::fprintf(stderr, "fractions cover %.17g m2, area is %.17g m2\n", covered, a);
      std::abort();
    }
  }
  if (area.SegmentLengthInInterior(lo, hi) > std::hypot(hi.x - lo.x, hi.y - lo.y) * (1 + 1e-9)) {
    Fail("segment longer inside than it is", std::hypot(hi.x - lo.x, hi.y - lo.y));
  }

  const double res = extent / 30;
  auto centre = covplan::RasterizeArea(area, res, covplan::RasterRule::kCentre, 4096);
  auto inside = covplan::RasterizeArea(area, res, covplan::RasterRule::kInside, 4096);
  Check(centre.status(), "RasterizeArea");
  Check(inside.status(), "RasterizeArea");
  if (centre.ok() != inside.ok()) Fail("raster rules disagree on the image", res);
  if (!centre.ok()) return;
  if (centre->width() != inside->width() || centre->height() != inside->height()) {
    Fail("raster rules give different sizes", res);
  }
  const covplan::Point2 o = centre->origin();
  for (int r = 0; r < inside->height(); ++r) {
    for (int c = 0; c < inside->width(); ++c) {
      if (inside->IsFree(r, c) && !centre->IsFree(r, c)) Fail("kInside pixel not kCentre", r);
      if (inside->at(r, c) == covplan::CellState::kUnknown) Fail("unknown pixel", r);
      if ((r * 31 + c * 17) % 29 != 0) continue;  // point tests on a sample of pixels
      const covplan::Point2 mid{o.x + (c + 0.5) * res, o.y + (r + 0.5) * res};
      if (centre->IsFree(r, c) != area.Contains(mid)) Fail("kCentre pixel disagrees", c);
      // kInside is conservative up to 1e-9 of a pixel, and corners on the boundary may round
      // either way: test them pulled 1e-6 of a pixel towards the centre.
      const auto corner_in = [&](double fx, double fy) {
        const double e = 1e-6 * res;
        return area.Contains(
            {o.x + (c + fx) * res + (fx > 0 ? -e : e), o.y + (r + fy) * res + (fy > 0 ? -e : e)});
      };
      if (inside->IsFree(r, c) &&
          !(corner_in(0, 0) && corner_in(1, 0) && corner_in(0, 1) && corner_in(1, 1))) {
        Fail("kInside pixel with a corner outside", c);
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<std::vector<covplan::PolygonInput>> polygons =
      covplan::ParseGeoJsonPolygons(json, "fuzz.geojson", 1 << 16);
  Check(polygons.status(), "ParseGeoJsonPolygons");
  if (!polygons.ok()) return 0;
  covplan::AreaLimits limits;
  limits.max_vertices = 2000;
  absl::StatusOr<covplan::Area> area = covplan::Area::Create(*polygons, "polygons", limits);
  Check(area.status(), "Area::Create");
  if (area.ok() && !area->empty()) CheckArea(*area);
  return 0;
}
