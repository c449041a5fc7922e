// The replanning half of the proto edge (convert.h): progress, obstacles and
// methods in; the replanned plan and its statistics out.
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"
#include "api/convert.h"
#include "planner/common/status_macros.h"

namespace covplan {

absl::StatusOr<ReplanMethod> ReplanMethodFromProto(v1::ReplanMethod m) {
  switch (m) {
    case v1::REPLAN_METHOD_UNSPECIFIED:
    case v1::AUTO:
      return ReplanMethod::kAuto;
    case v1::ILP1:
      return ReplanMethod::kIlp1;
    case v1::ILP2:
      return ReplanMethod::kIlp2;
    case v1::GREEDY_DETOUR:
      return ReplanMethod::kGreedyDetour;
    case v1::FULL:
      return ReplanMethod::kFull;
    default:
      return absl::InvalidArgumentError(
          absl::StrFormat("method: unknown value %d", static_cast<int>(m)));
  }
}

absl::StatusOr<RobotProgress> ProgressFromProto(const v1::RobotProgress& p) {
  RobotProgress out;
  if (p.waypoint() < 0) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "progress.waypoint must be >= 1 (or 0 with distance_m), got %d", p.waypoint()));
  }
  if (p.waypoint() > 0) {
    out.waypoint = p.waypoint();
    if (!p.has_position()) {
      return absl::InvalidArgumentError("progress.position is required with progress.waypoint");
    }
    out.position = Point2{p.position().x(), p.position().y()};
  }
  if (p.has_distance_m()) out.distance_m = p.distance_m();
  if (p.has_tolerance_m()) out.tolerance_m = p.tolerance_m();
  return out;
}

v1::ReplanMethod ReplanMethodToProto(ReplanMethod m) {
  switch (m) {
    case ReplanMethod::kAuto:
      return v1::AUTO;
    case ReplanMethod::kIlp1:
      return v1::ILP1;
    case ReplanMethod::kIlp2:
      return v1::ILP2;
    case ReplanMethod::kGreedyDetour:
      return v1::GREEDY_DETOUR;
    case ReplanMethod::kFull:
      return v1::FULL;
  }
  return v1::AUTO;
}

void ProgressToProto(const RobotProgress& at, v1::RobotProgress* out) {
  if (at.waypoint >= 1) out->set_waypoint(at.waypoint);
  if (at.distance_m) out->set_distance_m(*at.distance_m);
  if (at.position) {
    out->mutable_position()->set_x(at.position->x);
    out->mutable_position()->set_y(at.position->y);
  }
  if (at.tolerance_m) out->set_tolerance_m(*at.tolerance_m);
}

ReplanStats ReplanStatsFromProto(const v1::ReplanStats& s) {
  ReplanStats out;
  out.method = s.method();
  out.num_encounters = s.num_encounters();
  out.greedy_detours.assign(s.greedy_detours().begin(), s.greedy_detours().end());
  out.replanned_encounter = s.replanned_encounter();
  out.time_to_encounter_s = s.time_to_encounter_s();
  out.rank_budget = s.rank_budget();
  out.new_ranks = s.new_ranks();
  out.kept_ranks = s.kept_ranks();
  out.kept_path_pieces = s.kept_path_pieces();
  out.kept_path_m = s.kept_path_m();
  out.newly_blocked_cells = s.newly_blocked_cells();
  out.covered_cells_before = s.covered_cells_before();
  out.remaining_cells = s.remaining_cells();
  out.newly_unreachable_cells = s.newly_unreachable_cells();
  out.newly_obstructed_cells = s.newly_obstructed_cells();
  out.remaining_free_area_m2 = s.remaining_free_area_m2();
  out.rank_replan_ms = s.rank_replan_ms();
  out.transitions_ms = s.transitions_ms();
  out.tour_ms = s.tour_ms();
  out.total_ms = s.total_ms();
  out.end_moved = s.end_moved();
  out.robot_cell_blocked = s.robot_cell_blocked();
  out.robot_cell_kept_free = s.robot_cell_kept_free();
  return out;
}

Observations ObstaclesFromProto(const v1::Obstacles& o) {
  Observations out;
  for (const v1::CellRef& c : o.cells()) out.cells.push_back({c.row(), c.col()});
  for (const v1::Point2& p : o.points()) out.points.push_back({p.x(), p.y()});
  out.polygons = PolygonsFromProto(o.polygons());
  return out;
}

void ReplanToProto(const ReplanResult& result, const RetainedPlan& retained,
                   v1::ReplanResponse* out) {
  RetainedPlanToProto(retained, out->mutable_plan());
  const ReplanStats& s = result.stats;
  v1::ReplanStats* o = out->mutable_replan();
  o->set_method(s.method);
  o->set_num_encounters(s.num_encounters);
  for (int k : s.greedy_detours) o->add_greedy_detours(k);
  o->set_replanned_encounter(s.replanned_encounter);
  o->set_time_to_encounter_s(s.time_to_encounter_s);
  o->set_rank_budget(static_cast<int32_t>(std::min<int64_t>(s.rank_budget, INT32_MAX)));
  o->set_new_ranks(static_cast<int32_t>(s.new_ranks));
  o->set_kept_ranks(static_cast<int32_t>(s.kept_ranks));
  o->set_kept_path_pieces(static_cast<int32_t>(s.kept_path_pieces));
  o->set_kept_path_m(s.kept_path_m);
  o->set_newly_blocked_cells(static_cast<int32_t>(s.newly_blocked_cells));
  o->set_covered_cells_before(static_cast<int32_t>(s.covered_cells_before));
  o->set_remaining_cells(static_cast<int32_t>(s.remaining_cells));
  o->set_newly_unreachable_cells(static_cast<int32_t>(s.newly_unreachable_cells));
  o->set_newly_obstructed_cells(static_cast<int32_t>(s.newly_obstructed_cells));
  o->set_remaining_free_area_m2(s.remaining_free_area_m2);
  o->set_rank_replan_ms(s.rank_replan_ms);
  o->set_transitions_ms(s.transitions_ms);
  o->set_tour_ms(s.tour_ms);
  o->set_total_ms(s.total_ms);
  o->set_complete(s.newly_unreachable_cells == 0);
  o->set_end_moved(s.end_moved);
  o->set_robot_cell_blocked(s.robot_cell_blocked);
  o->set_robot_cell_kept_free(s.robot_cell_kept_free);
  for (const CellIndex& c : result.unreachable) {
    v1::CellRef* r = out->add_unreachable();
    r->set_row(c.row);
    r->set_col(c.col);
  }
}

absl::StatusOr<RetainedPlan> RetainedPlanFromInline(const v1::InlinePlan& inline_plan,
                                                    const PlanningEngine& engine,
                                                    const MapSource& source,
                                                    const StopToken& stop) {
  ASSIGN_OR_RETURN(PlanRequest request, PlanRequestFromProto(inline_plan.request()));
  request.common.stop = stop;  // a cold grid build on a restarted server is bounded too
  ASSIGN_OR_RETURN(std::shared_ptr<const CoverageArea> area, engine.AreaFor(source, request));
  ASSIGN_OR_RETURN(CoveragePlan plan, PlanFromProto(inline_plan.plan()));
  const Grid& g = *plan.grid;
  const Grid& drive = *area->drive;
  if (g.rows() != drive.rows() || g.cols() != drive.cols() ||
      std::abs(g.cell_size() - drive.cell_size()) > 1e-9) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "plan.plan.grid (%d x %d cells of %g m) does not match the map at this tool width "
        "(%d x %d cells of %g m)",
        g.rows(), g.cols(), g.cell_size(), drive.rows(), drive.cols(), drive.cell_size()));
  }
  // The inline plan's grid may have lost cells to earlier replans: keep the
  // area's barriers and obstacle pixels, with the plan's free cells. What it
  // still has to cover is what its sweeps cover (a replanned plan covers only
  // the remainder of its mission).
  std::vector<uint8_t> free = drive.free_flags(), cover(free.size(), 0);
  for (size_t i = 0; i < free.size(); ++i) free[i] = free[i] && g.free_flags()[i];
  for (const CoverageSweep& s : plan.sweeps) {
    for (const CellIndex& c : s.cells) {
      const int64_t i = drive.Index(c.row, c.col);
      cover[i] = area->cover->free_flags()[i] && free[i];
    }
  }
  auto derived = std::make_shared<CoverageArea>(*area);
  int64_t cover_cells = 0;
  for (uint8_t c : cover) cover_cells += c;
  derived->drive = std::make_shared<const Grid>(drive.WithFreeFlags(std::move(free)));
  derived->cover = std::make_shared<const Grid>(drive.WithFreeFlags(std::move(cover)));
  derived->cover_cells = cover_cells;
  // Cells earlier replans cut off stay counted (the plan says how many).
  derived->unreachable_cells =
      std::max<int64_t>(area->unreachable_cells, plan.stats.unreachable_free_cells);
  plan.grid = derived->drive;
  RetainedPlan out;
  out.plan_id = inline_plan.plan().plan_id();
  out.map_id = source.map_id;
  out.plan = std::move(plan);
  out.request = std::move(request);
  out.request.common.stop = StopToken();
  out.area = std::move(derived);
  return out;
}

}  // namespace covplan
