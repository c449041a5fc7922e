#include "planner/engine/site.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/grid_paths.h"

namespace covplan {
namespace {

constexpr double kMinResolution = 1e-4;  // metres per pixel
constexpr double kMaxResolution = 1000.0;
constexpr double kMaxCoordinate = 1e7;  // metres from the map frame's origin

double MsSince(absl::Time t) { return absl::ToDoubleMilliseconds(absl::Now() - t); }

uint64_t Fnv1a(const std::string& text) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : text) h = (h ^ ch) * 1099511628211ull;
  return h;
}

}  // namespace

Point2 SiteMap::min_corner() const { return raster ? raster->origin() : Point2{}; }

Point2 SiteMap::max_corner() const {
  if (!raster) return {};
  return {raster->origin().x + raster->width() * raster->resolution(),
          raster->origin().y + raster->height() * raster->resolution()};
}

absl::StatusOr<SiteMap> SiteFromPolygons(std::shared_ptr<const Area> free_space, double resolution,
                                         int64_t max_pixels) {
  if (free_space == nullptr || free_space->empty()) {
    return absl::InvalidArgumentError("map.polygons: the map has no polygon (no free space)");
  }
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "map.polygons.resolution must be a positive number of metres, got %g", resolution));
  }
  const Point2 lo = free_space->min_corner(), hi = free_space->max_corner();
  const double pixels = ((hi.x - lo.x) / resolution + 2) * ((hi.y - lo.y) / resolution + 2);
  if (pixels > static_cast<double>(max_pixels)) {
    // Coarsen to fit: the raster only serves obstacle checks; free cells come
    // from the exact polygon areas.
    resolution *= std::sqrt(pixels / static_cast<double>(max_pixels)) * 1.01;
  }
  ASSIGN_OR_RETURN(OccupancyMap raster,
                   RasterizeArea(*free_space, resolution, RasterRule::kInside, max_pixels));
  SiteMap site;
  site.raster = std::make_shared<const OccupancyMap>(std::move(raster));
  site.polygons = std::move(free_space);
  return site;
}

absl::Status CheckSiteGeometry(const SiteMap& site) {
  if (site.raster == nullptr) return absl::InvalidArgumentError("map has no raster");
  const double resolution = site.raster->resolution();
  if (!std::isfinite(resolution) || resolution < kMinResolution || resolution > kMaxResolution) {
    return absl::InvalidArgumentError(
        absl::StrFormat("map resolution %g m/px is outside [%g, %g] m/px", resolution,
                        kMinResolution, kMaxResolution));
  }
  const Point2 corners[2] = {site.min_corner(), site.max_corner()};
  for (const Point2& p : corners) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || std::abs(p.x) > kMaxCoordinate ||
        std::abs(p.y) > kMaxCoordinate) {
      return absl::InvalidArgumentError(
          absl::StrFormat("map origin/extent (%g, %g) m is beyond %g m from the map frame's origin",
                          p.x, p.y, kMaxCoordinate));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<const GridArtifact>> BuildGridArtifact(const SiteMap& site,
                                                                      const GridOptions& options) {
  if (site.raster == nullptr) return absl::InternalError("site map without raster");
  RETURN_IF_ERROR(CheckSiteGeometry(site));
  const absl::Time start = absl::Now();
  const OccupancyMap& map = *site.raster;
  ASSIGN_OR_RETURN(GridFrame frame, PlanGridFrame(map, options));
  std::vector<double> fractions;
  double free_area = 0.0;
  if (site.polygons != nullptr) {
    const std::vector<float> f =
        CellOverlapFractions(*site.polygons, frame.rows, frame.cols, frame.cell_size, frame.origin);
    fractions.assign(f.begin(), f.end());
    free_area = site.polygons->AreaM2();
  } else {
    fractions = CellFreeFractions(map, frame);
    free_area = map.FreeAreaM2();
  }
  ASSIGN_OR_RETURN(Grid grid, BuildGridFromFractions(map, options, frame, fractions));
  auto artifact = std::make_shared<GridArtifact>();
  artifact->grid = std::make_shared<const Grid>(std::move(grid));
  artifact->free_fraction.assign(fractions.begin(), fractions.end());
  artifact->map_free_area_m2 = free_area;
  artifact->build_ms = MsSince(start);
  return std::shared_ptr<const GridArtifact>(std::move(artifact));
}

std::string AreaZones::CacheText() const {
  if (!has_regions() && !has_no_go()) return "none";
  // The canonical geometry text can be long; its hash and size identify it.
  std::string out;
  if (has_regions()) {
    const std::string t = regions->CanonicalText();
    absl::StrAppend(&out, "regions=", absl::StrFormat("%016x:%d", Fnv1a(t), t.size()));
  }
  if (has_no_go()) {
    const std::string t = no_go->CanonicalText();
    absl::StrAppend(&out, out.empty() ? "" : ";",
                    "no_go=", absl::StrFormat("%016x:%d", Fnv1a(t), t.size()));
  }
  return out;
}

absl::StatusOr<std::shared_ptr<const CoverageArea>> BuildCoverageArea(const GridArtifact& g,
                                                                      const AreaZones& zones,
                                                                      double min_free_fraction) {
  const absl::Time start = absl::Now();
  const Grid& grid = *g.grid;
  const int rows = grid.rows(), cols = grid.cols();
  const size_t n = static_cast<size_t>(grid.size());
  std::vector<uint8_t> drive = grid.free_flags();
  auto out = std::make_shared<CoverageArea>();
  out->zones = zones;
  out->map_free_area_m2 = g.map_free_area_m2;

  // No-go: every cell whose square overlaps a zone's interior is closed, so a
  // straight move between free cell centres (which only touches free cells)
  // never enters a zone.
  std::vector<float> no_go(n, 0.0f);
  if (zones.has_no_go()) {
    no_go = CellOverlapFractions(*zones.no_go, rows, cols, grid.cell_size(), grid.origin());
    for (size_t i = 0; i < n; ++i) {
      if (drive[i] && no_go[i] > 0.0f) drive[i] = 0, ++out->no_go_cells;
    }
  }
  std::vector<float> region(n, 1.0f);
  if (zones.has_regions()) {
    region = CellOverlapFractions(*zones.regions, rows, cols, grid.cell_size(), grid.origin());
  }
  std::vector<uint8_t> cover(n, 0);
  int64_t any_region_cell = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool in_target = !zones.has_regions() || region[i] > min_free_fraction;
    cover[i] = drive[i] && in_target;
    any_region_cell += cover[i];
  }
  if (any_region_cell == 0) {
    return absl::InvalidArgumentError(
        zones.has_regions()
            ? absl::StrFormat("regions: no free %g m cell lies mostly inside the regions (outside "
                              "no-go zones): nothing to cover",
                              grid.cell_size())
            : std::string("no_go: the no-go zones close every free cell: nothing to cover"));
  }

  // Keep the drive component holding the most cells to cover.
  const Grid drive_all = grid.WithFreeFlags(drive);
  int32_t num = 0;
  const std::vector<int32_t> comp = FreeComponents(drive_all, &num);
  std::vector<int64_t> weight(num, 0), size(num, 0);
  for (size_t i = 0; i < n; ++i) {
    if (comp[i] < 0) continue;
    weight[comp[i]] += cover[i];
    ++size[comp[i]];
  }
  int32_t keep = 0;
  for (int32_t c = 1; c < num; ++c) {
    if (weight[c] > weight[keep] || (weight[c] == weight[keep] && size[c] > size[keep])) keep = c;
  }
  double target = 0.0, covered = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double share = static_cast<double>(g.free_fraction[i]) * region[i] * (1.0 - no_go[i]);
    target += share;
    const bool kept = comp[i] == keep;
    if (!kept) {
      out->unreachable_cells += cover[i];
      drive[i] = 0;
      cover[i] = 0;
    } else if (cover[i]) {
      covered += share;
      ++out->cover_cells;
    }
  }
  out->covered_free_area_ratio = target > 0.0 ? std::min(1.0, covered / target) : 0.0;
  if (!zones.has_regions() && !zones.has_no_go()) {
    // Without zones the target is the map's free area itself.
    const double cell_m2 = grid.cell_size() * grid.cell_size();
    out->covered_free_area_ratio =
        g.map_free_area_m2 > 0.0 ? std::min(1.0, covered * cell_m2 / g.map_free_area_m2) : 0.0;
  }
  out->drive = std::make_shared<const Grid>(grid.WithFreeFlags(std::move(drive)));
  out->cover = std::make_shared<const Grid>(grid.WithFreeFlags(std::move(cover)));
  out->grid_ms = g.build_ms + MsSince(start);
  return std::shared_ptr<const CoverageArea>(std::move(out));
}

}  // namespace covplan
