// `covplan plan`'s and `covplan export`'s export flags: --out-geojson, --out-csv, --out-nav-path
// (with --frame-id and --nav-stamp), written from the plan's response by
// api/plan_export.h.
//
//   ASSIGN_OR_RETURN(PlanExports exports, PlanExportsFromFlags(args));
//   RETURN_IF_ERROR(WritePlanExports(exports, response));
#ifndef COVPLAN_CLIENT_PLAN_EXPORTS_H_
#define COVPLAN_CLIENT_PLAN_EXPORTS_H_

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "api/plan_export.h"
#include "client/args.h"
#include "covplan/v1/covplan.pb.h"

namespace covplan {

struct PlanExports {
  std::optional<std::string> geojson;
  std::optional<std::string> csv;
  std::optional<std::string> nav_path;
  NavPathOptions nav;
  bool any() const { return geojson || csv || nav_path; }
};

// The value flags read here (for the command's flag set and help).
std::set<std::string> PlanExportFlags();
absl::StatusOr<PlanExports> PlanExportsFromFlags(const ParsedArgs& a);
// The nav path is always in the plan's frame; `frame` takes the GeoJSON and
// CSV positions back into the site's CRS (client/geo_site.h).
absl::Status WritePlanExports(const PlanExports& exports, const v1::PlanResponse& plan,
                              const ExportFrame& frame = {});

// `covplan export --plan FILE [--robot ID] [--map F --crs CRS] <export flags>`:
// the exports of a plan.json (covplan plan --out, a GetPlan reply), or of one
// robot's plan in a fleet JSON (covplan plan --robot ... --out); with --crs,
// in the CRS of the geographic map the plan was made on.
int RunExportCommand(const std::vector<std::string>& args);

}  // namespace covplan

#endif  // COVPLAN_CLIENT_PLAN_EXPORTS_H_
