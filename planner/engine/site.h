// The per-map artifacts every planner starts from.
//
//   SiteMap            the map as given: an occupancy raster, or polygons
//                      (then also a conservative raster for obstacle checks)
//   GridArtifact       the tool-width grid over the whole map, with each
//                      cell's free share; keyed by map id + grid options
//   CoverageArea       what a request plans on: the drive grid (no-go zones
//                      closed, one connected component kept) and the cover
//                      grid (the drive grid's cells to sweep: in the regions,
//                      when given); derived from a GridArtifact, keyed by the
//                      parent's key + the zones, so a zone-less request for
//                      the same map still shares the grid
//
//   ASSIGN_OR_RETURN(auto grid, BuildGridArtifact(site, grid_options));  // checks the site
//   ASSIGN_OR_RETURN(auto area, BuildCoverageArea(*grid, zones, min_free_fraction));
//
// Thread-safety: all artifacts are immutable after construction; the
// functions are reentrant.
#ifndef COVPLAN_PLANNER_ENGINE_SITE_H_
#define COVPLAN_PLANNER_ENGINE_SITE_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "planner/engine/artifact_cache.h"
#include "planner/geometry/area.h"
#include "planner/grid/grid.h"
#include "planner/grid/occupancy_map.h"

namespace covplan {

struct SiteMap {
  // The occupancy raster. For a polygon map: the free space drawn so that a
  // pixel is free only when it lies wholly inside (obstacle checks stay
  // conservative).
  std::shared_ptr<const OccupancyMap> raster;
  // Polygon maps only: the free space itself; cells are free by their exact
  // area fraction inside it.
  std::shared_ptr<const Area> polygons;

  // Map extent in the map frame.
  Point2 min_corner() const;
  Point2 max_corner() const;
};

// Draws a polygon map's free space at `resolution` (m/px; coarsened so that
// the raster stays within max_pixels) into a SiteMap.
absl::StatusOr<SiteMap> SiteFromPolygons(std::shared_ptr<const Area> free_space, double resolution,
                                         int64_t max_pixels);

// InvalidArgument unless the map's resolution and extent are finite and of
// a size a robot can plan on (resolution 0.1 mm .. 1 km per pixel, every
// corner within 10,000 km of the origin). BuildGridArtifact checks it, so
// every entry point refuses such a map alike; a host that stores maps calls
// it before storing one.
absl::Status CheckSiteGeometry(const SiteMap& site);

class GridArtifact final : public Artifact {
 public:
  std::shared_ptr<const Grid> grid;  // every free cell, all components
  std::vector<float> free_fraction;  // per cell: free share of its area
  double map_free_area_m2 = 0.0;
  double build_ms = 0.0;
  size_t MemoryBytes() const override {
    return sizeof(*this) + (grid ? grid->MemoryBytes() : 0) +
           free_fraction.capacity() * sizeof(float);
  }
};

// Checks the site first (CheckSiteGeometry).
absl::StatusOr<std::shared_ptr<const GridArtifact>> BuildGridArtifact(const SiteMap& site,
                                                                      const GridOptions& options);

// Where to cover and where never to go, as validated areas (empty = none).
struct AreaZones {
  std::shared_ptr<const Area> regions;  // cover only cells mostly inside these
  std::shared_ptr<const Area> no_go;    // never enter, to cover or to pass
  bool has_regions() const { return regions != nullptr && !regions->empty(); }
  bool has_no_go() const { return no_go != nullptr && !no_go->empty(); }
  // Stable text for cache keys ("none" without zones).
  std::string CacheText() const;
};

class CoverageArea final : public Artifact {
 public:
  // Free cells the robot may drive on: no cell overlapping a no-go zone,
  // only the component that holds the most cells to cover.
  std::shared_ptr<const Grid> drive;
  // The drive grid's cells to sweep (all of them without regions; with
  // regions, those more than half inside a region). Same shape as `drive`.
  std::shared_ptr<const Grid> cover;
  AreaZones zones;
  int64_t cover_cells = 0;
  int64_t unreachable_cells = 0;  // cells to cover outside the kept component
  int64_t no_go_cells = 0;        // free cells closed by no-go zones
  double map_free_area_m2 = 0.0;
  // Share of the target free area (the map, or the regions, less no-go
  // zones) inside the cells to cover. Exact without regions; with regions an
  // area-weighted estimate (free pixels assumed even within a cell).
  double covered_free_area_ratio = 0.0;
  double grid_ms = 0.0;  // grid build + this derivation
  size_t MemoryBytes() const override {
    return sizeof(*this) + (drive ? drive->MemoryBytes() : 0) +
           (cover ? cover->size() + sizeof(Grid) : 0);
  }
};

// InvalidArgument when a region has no free cell or nothing is left to cover.
absl::StatusOr<std::shared_ptr<const CoverageArea>> BuildCoverageArea(const GridArtifact& grid,
                                                                      const AreaZones& zones,
                                                                      double min_free_fraction);

}  // namespace covplan

#endif  // COVPLAN_PLANNER_ENGINE_SITE_H_
