// `--crs CRS` of `covplan plan` and `covplan export`: the map (a GeoJSON
// polygon map) and every coordinate the command is given (zones, poses, the
// fleet's robots) are in CRS, e.g. EPSG:4326 for longitude/latitude drawn on
// a web map or a UTM zone. They are projected into the site's local metric
// frame (api/geo_frame.h) before planning; plan.json and the nav path stay in
// that frame, the GeoJSON and CSV exports go back into CRS.
//
//   ASSIGN_OR_RETURN(std::optional<GeoFrame> frame, ProjectIntoSite(crs, &map, &request, &fleet));
//   RETURN_IF_ERROR(WritePlanExports(exports, response, ExportFrameOf(frame)));
#ifndef COVPLAN_CLIENT_GEO_SITE_H_
#define COVPLAN_CLIENT_GEO_SITE_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "api/geo_frame.h"
#include "api/plan_export.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/fleet/fleet_request.h"

namespace covplan {

// nullopt without a CRS. InvalidArgument for a raster map, a CRS PROJ does not
// know, or a position outside it (naming the field and vertex).
absl::StatusOr<std::optional<GeoFrame>> ProjectIntoSite(const std::optional<std::string>& crs,
                                                        v1::Map* map, v1::PlanRequest* request,
                                                        std::vector<FleetRobot>* fleet = nullptr);

// The site's frame as the exports' way back into its CRS (identity without one).
ExportFrame ExportFrameOf(const std::optional<GeoFrame>& frame);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_GEO_SITE_H_
