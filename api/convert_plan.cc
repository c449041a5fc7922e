// The plan half of the proto edge (convert.h): CoveragePlan <-> PlanResponse
// and the canonical JSON of plan.json.
#include "api/convert.h"

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api/convert_stc.h"
#include "google/protobuf/util/json_util.h"
#include "planner/boustrophedon/boustrophedon_planner.h"
#include "planner/common/status_macros.h"
#include "planner/grid/grid.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/partition/rank.h"
#include "planner/tour/path_timing.h"

namespace covplan {

namespace {

v1::SegmentKind KindToProto(SegmentKind k) {
  switch (k) {
    case SegmentKind::kStart:
      return v1::START;
    case SegmentKind::kCoverage:
      return v1::COVERAGE;
    case SegmentKind::kTransition:
      return v1::TRANSITION;
    case SegmentKind::kToStation:
      return v1::TO_STATION;
    case SegmentKind::kFromStation:
      return v1::FROM_STATION;
  }
  return v1::SEGMENT_KIND_UNSPECIFIED;
}

absl::StatusOr<SegmentKind> KindFromProto(v1::SegmentKind k) {
  switch (k) {
    case v1::START:
      return SegmentKind::kStart;
    case v1::COVERAGE:
      return SegmentKind::kCoverage;
    case v1::TRANSITION:
      return SegmentKind::kTransition;
    case v1::TO_STATION:
      return SegmentKind::kToStation;
    case v1::FROM_STATION:
      return SegmentKind::kFromStation;
    default:
      return absl::InvalidArgumentError("plan waypoint has no segment kind");
  }
}

void RankToProto(const Rank& rank, v1::Rank* r) {
  r->set_orientation(rank.orientation == Orientation::kHorizontal ? v1::HORIZONTAL : v1::VERTICAL);
  r->mutable_first_cell()->set_row(rank.first.row);
  r->mutable_first_cell()->set_col(rank.first.col);
  r->mutable_last_cell()->set_row(rank.last.row);
  r->mutable_last_cell()->set_col(rank.last.col);
}

v1::TerminationLimit LimitToProto(TerminationLimit l) {
  switch (l) {
    case TerminationLimit::kNone:
      return v1::LIMIT_NONE;
    case TerminationLimit::kTime:
      return v1::LIMIT_TIME;
    case TerminationLimit::kDeadline:
      return v1::LIMIT_DEADLINE;
    case TerminationLimit::kCancelled:
      return v1::LIMIT_CANCELLED;
  }
  return v1::TERMINATION_LIMIT_UNSPECIFIED;
}

v1::PlanSource PlanOriginToProto(PlanOrigin s) {
  switch (s) {
    case PlanOrigin::kCold:
      return v1::PLAN_SOURCE_COLD;
    case PlanOrigin::kCacheHit:
      return v1::PLAN_SOURCE_CACHE_HIT;
    case PlanOrigin::kImproved:
      return v1::PLAN_SOURCE_IMPROVED;
    case PlanOrigin::kWarmStart:
      return v1::PLAN_SOURCE_WARM_START;
  }
  return v1::PLAN_SOURCE_UNSPECIFIED;
}

PlanOrigin PlanOriginFromProto(v1::PlanSource s) {
  switch (s) {
    case v1::PLAN_SOURCE_CACHE_HIT:
      return PlanOrigin::kCacheHit;
    case v1::PLAN_SOURCE_IMPROVED:
      return PlanOrigin::kImproved;
    case v1::PLAN_SOURCE_WARM_START:
      return PlanOrigin::kWarmStart;
    default:
      return PlanOrigin::kCold;
  }
}

// The grid's rows, checked for shape and '0'/'1' cells.
absl::StatusOr<std::shared_ptr<const Grid>> GridFromProto(const v1::Grid& g) {
  if (g.rows() <= 0 || g.cols() <= 0 || g.free_cells_size() != g.rows()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("plan grid is inconsistent: %d rows x %d cols with %d row strings",
                        g.rows(), g.cols(), g.free_cells_size()));
  }
  if (!std::isfinite(g.cell_size_m()) || g.cell_size_m() <= 0.0) {
    return absl::InvalidArgumentError("plan grid cell_size_m must be positive");
  }
  std::vector<uint8_t> free;
  free.reserve(static_cast<size_t>(g.rows()) * g.cols());
  for (const std::string& row : g.free_cells()) {
    if (static_cast<int>(row.size()) != g.cols()) {
      return absl::InvalidArgumentError("plan grid row length differs from cols");
    }
    for (char c : row) {
      if (c != '0' && c != '1') return absl::InvalidArgumentError("plan grid rows must be '0'/'1'");
      free.push_back(c == '1');
    }
  }
  return std::make_shared<const Grid>(g.rows(), g.cols(), g.cell_size_m(),
                                      Point2{g.origin_x_m(), g.origin_y_m()}, std::move(free));
}

// The OARP detail: the oneof, or (older servers) the top-level rank fields;
// null when the response has neither.
absl::StatusOr<std::shared_ptr<const PlannerDetail>> OarpDetailFromProto(
    const v1::PlanResponse& response, const Grid& grid) {
  const bool has_oarp = response.has_oarp();
  const auto& ranks = has_oarp ? response.oarp().ranks() : response.ranks();
  const auto& order = has_oarp ? response.oarp().rank_order() : response.rank_order();
  const auto& reversed = has_oarp ? response.oarp().rank_reversed() : response.rank_reversed();
  if (!has_oarp && ranks.empty()) return std::shared_ptr<const PlannerDetail>();
  auto detail = std::make_shared<OarpDetail>();
  for (const v1::Rank& r : ranks) {
    Rank rank;
    if (r.orientation() != v1::HORIZONTAL && r.orientation() != v1::VERTICAL) {
      return absl::InvalidArgumentError("plan rank has no orientation");
    }
    rank.orientation =
        r.orientation() == v1::HORIZONTAL ? Orientation::kHorizontal : Orientation::kVertical;
    rank.first = {r.first_cell().row(), r.first_cell().col()};
    rank.last = {r.last_cell().row(), r.last_cell().col()};
    if (!grid.InBounds(rank.first.row, rank.first.col) ||
        !grid.InBounds(rank.last.row, rank.last.col)) {
      return absl::InvalidArgumentError("plan rank lies outside the grid");
    }
    detail->ranks.push_back(rank);
  }
  for (int32_t index : order) {
    if (index < 0 || index >= static_cast<int>(detail->ranks.size())) {
      return absl::InvalidArgumentError("plan rank_order refers to a missing rank");
    }
    detail->rank_order.push_back(index);
  }
  detail->rank_reversed.assign(reversed.begin(), reversed.end());
  return std::shared_ptr<const PlannerDetail>(std::move(detail));
}

absl::StatusOr<std::shared_ptr<const PlannerDetail>> BoustrophedonDetailFromProto(
    const v1::BoustrophedonDetail& b, const Grid& grid) {
  auto detail = std::make_shared<BoustrophedonDetail>();
  for (const v1::BoustrophedonCell& c : b.cells()) {
    if (c.row_lo_size() != c.row_hi_size() || c.first_col() < 0 ||
        c.first_col() + c.row_lo_size() > grid.cols()) {
      return absl::InvalidArgumentError("plan boustrophedon cell lies outside the grid");
    }
    BoustrophedonCellInfo info;
    info.cell.first_col = c.first_col();
    for (int k = 0; k < c.row_lo_size(); ++k) {
      if (c.row_lo(k) < 0 || c.row_lo(k) > c.row_hi(k) || c.row_hi(k) >= grid.rows()) {
        return absl::InvalidArgumentError("plan boustrophedon cell lies outside the grid");
      }
      info.cell.columns.push_back({c.row_lo(k), c.row_hi(k)});
    }
    info.axis =
        c.axis() == v1::SWEEP_AXIS_HORIZONTAL ? SweepAxis::kHorizontal : SweepAxis::kVertical;
    info.num_lines = c.num_lines();
    detail->cells.push_back(std::move(info));
  }
  for (int32_t index : b.cell_order()) {
    if (index < 0 || index >= static_cast<int>(detail->cells.size())) {
      return absl::InvalidArgumentError("plan cell_order refers to a missing cell");
    }
    detail->cell_order.push_back(index);
  }
  detail->cell_reversed.assign(b.cell_reversed().begin(), b.cell_reversed().end());
  detail->cell_mirrored.assign(b.cell_mirrored().begin(), b.cell_mirrored().end());
  return std::shared_ptr<const PlannerDetail>(std::move(detail));
}

// The path, then the sweeps (which refer to its waypoints), into `plan`.
absl::Status PathFromProto(const v1::PlanResponse& response, CoveragePlan* plan) {
  for (const v1::Waypoint& p : response.path()) {
    Waypoint w;
    w.x = p.x();
    w.y = p.y();
    w.theta = p.theta();
    absl::StatusOr<SegmentKind> kind = KindFromProto(p.kind());
    if (!kind.ok()) return kind.status();
    w.kind = *kind;
    w.rank = p.rank();
    plan->path.push_back(w);
  }
  for (const v1::CoverageSweep& s : response.sweeps()) {
    if (s.waypoint() < 0 || s.waypoint() >= static_cast<int>(plan->path.size())) {
      return absl::InvalidArgumentError("plan sweep refers to a missing waypoint");
    }
    CoverageSweep sweep;
    sweep.waypoint = s.waypoint();
    for (int32_t cell : s.cells()) {
      if (cell < 0 || cell >= plan->grid->size()) {
        return absl::InvalidArgumentError("plan sweep cell lies outside the grid");
      }
      sweep.cells.push_back(plan->grid->FromIndex(cell));
    }
    plan->sweeps.push_back(std::move(sweep));
  }
  return absl::OkStatus();
}

PlanStats PlanStatsFromProto(const v1::PlanStats& s) {
  PlanStats o;
  o.num_ranks = s.num_ranks();
  o.num_turns = s.num_turns();
  o.coverage_length_m = s.coverage_length_m();
  o.transition_length_m = s.transition_length_m();
  o.covered_free_area_ratio = s.covered_free_area_ratio();
  o.estimated_duration_s = s.estimated_duration_s();
  o.turning_time_s = s.turning_time_s();
  o.planning_ms = s.planning_ms();
  o.grid_ms = s.grid_ms();
  o.partition_ms = s.partition_ms();
  o.transitions_ms = s.transitions_ms();
  o.tour_ms = s.tour_ms();
  o.free_cells = s.free_cells();
  o.grid_rows = s.grid_rows();
  o.grid_cols = s.grid_cols();
  o.map_free_area_m2 = s.map_free_area_m2();
  o.reachable_area_m2 = s.reachable_area_m2();
  o.swept_reachable_ratio = s.swept_reachable_ratio();
  o.missed_reachable_m2 = s.missed_reachable_m2();
  o.floor_ms = s.floor_ms();
  o.tour_cut_short = s.tour_cut_short();
  o.decomposition_cached = s.decomposition_cached();
  o.plan_source = PlanOriginFromProto(s.plan_source());
  o.partition_solver = s.partition_solver();
  o.tour_solver = s.tour_solver();
  o.unreachable_free_cells = s.unreachable_free_cells();
  o.covered_cells = s.covered_cells();
  o.no_go_cells = s.no_go_cells();
  o.mission_covered_cells = s.mission_covered_cells();
  o.mission_cut_off_cells = s.mission_cut_off_cells();
  o.mission_obstructed_cells = s.mission_obstructed_cells();
  o.charge_cycles = s.charge_cycles();
  o.energy_total = s.energy_total();
  o.energy_unconstrained = s.energy_unconstrained();
  o.energy_lower_bound = s.energy_lower_bound();
  return o;
}

// The charge cycles, checked against the path's length.
absl::StatusOr<std::vector<ChargeCycle>> CyclesFromProto(const v1::PlanResponse& response,
                                                         int num_waypoints) {
  std::vector<ChargeCycle> cycles;
  for (const v1::ChargeCycle& c : response.cycles()) {
    for (int w : {c.first_waypoint(), c.last_waypoint(), c.resume_waypoint(), c.leave_waypoint()}) {
      if (w < 0 || w >= num_waypoints)
        return absl::InvalidArgumentError("plan charge cycle refers to a missing waypoint");
    }
    cycles.push_back({c.first_waypoint(), c.last_waypoint(), c.resume_waypoint(),
                      c.leave_waypoint(), c.energy(), c.energy_at_leave(), c.resume_unit(),
                      c.resumes_mid_unit()});
  }
  return cycles;
}

}  // namespace

void TerminationToProto(const Termination& termination, v1::Termination* out) {
  out->set_reason(termination.reason == TerminationReason::kConverged ? v1::CONVERGED
                                                                      : v1::FEASIBLE_LIMIT_REACHED);
  out->set_limit(LimitToProto(termination.limit));
  out->set_detail(termination.detail);
}

Termination TerminationFromProto(const v1::Termination& t) {
  Termination out;
  out.reason = t.reason() == v1::FEASIBLE_LIMIT_REACHED ? TerminationReason::kFeasibleLimitReached
                                                        : TerminationReason::kConverged;
  switch (t.limit()) {
    case v1::LIMIT_TIME:
      out.limit = TerminationLimit::kTime;
      break;
    case v1::LIMIT_DEADLINE:
      out.limit = TerminationLimit::kDeadline;
      break;
    case v1::LIMIT_CANCELLED:
      out.limit = TerminationLimit::kCancelled;
      break;
    default:
      out.limit = TerminationLimit::kNone;
      break;
  }
  out.detail = t.detail();
  return out;
}

void PolygonsToProto(const std::vector<PolygonInput>& polygons,
                     google::protobuf::RepeatedPtrField<v1::Polygon>* out) {
  for (const PolygonInput& p : polygons) {
    v1::Polygon* poly = out->Add();
    for (const Point2& q : p.outer) {
      v1::Point2* pt = poly->mutable_outer()->add_points();
      pt->set_x(q.x);
      pt->set_y(q.y);
    }
    for (const auto& hole : p.holes) {
      v1::Ring* ring = poly->add_holes();
      for (const Point2& q : hole) {
        v1::Point2* pt = ring->add_points();
        pt->set_x(q.x);
        pt->set_y(q.y);
      }
    }
  }
}

std::vector<PolygonInput> PolygonsFromProto(
    const google::protobuf::RepeatedPtrField<v1::Polygon>& in) {
  std::vector<PolygonInput> out;
  out.reserve(in.size());
  for (const v1::Polygon& p : in) {
    PolygonInput poly;
    for (const v1::Point2& q : p.outer().points()) poly.outer.push_back({q.x(), q.y()});
    for (const v1::Ring& ring : p.holes()) {
      std::vector<Point2>& hole = poly.holes.emplace_back();
      for (const v1::Point2& q : ring.points()) hole.push_back({q.x(), q.y()});
    }
    out.push_back(std::move(poly));
  }
  return out;
}

void PlanToProto(const CoveragePlan& plan, v1::PlanResponse* out) {
  out->set_planner(plan.planner);
  if (plan.grid != nullptr) {
    const Grid& grid = *plan.grid;
    v1::Grid* g = out->mutable_grid();
    g->set_rows(grid.rows());
    g->set_cols(grid.cols());
    g->set_cell_size_m(grid.cell_size());
    g->set_origin_x_m(grid.origin().x);
    g->set_origin_y_m(grid.origin().y);
    for (std::string& row : grid.ToRowStrings()) g->add_free_cells(std::move(row));
  }
  if (const OarpDetail* oarp = plan.detail_as<OarpDetail>()) {
    v1::OarpDetail* d = out->mutable_oarp();
    for (const Rank& rank : oarp->ranks) {
      RankToProto(rank, out->add_ranks());
      RankToProto(rank, d->add_ranks());
    }
    for (int index : oarp->rank_order) out->add_rank_order(index), d->add_rank_order(index);
    for (bool reversed : oarp->rank_reversed) {
      out->add_rank_reversed(reversed);
      d->add_rank_reversed(reversed);
    }
  }
  if (const BoustrophedonDetail* bd = plan.detail_as<BoustrophedonDetail>()) {
    v1::BoustrophedonDetail* d = out->mutable_boustrophedon();
    for (const BoustrophedonCellInfo& info : bd->cells) {
      v1::BoustrophedonCell* c = d->add_cells();
      c->set_first_col(info.cell.first_col);
      for (const RowInterval& iv : info.cell.columns) c->add_row_lo(iv.lo), c->add_row_hi(iv.hi);
      c->set_axis(info.axis == SweepAxis::kHorizontal ? v1::SWEEP_AXIS_HORIZONTAL
                                                      : v1::SWEEP_AXIS_VERTICAL);
      c->set_num_lines(info.num_lines);
    }
    for (int index : bd->cell_order) d->add_cell_order(index);
    for (bool reversed : bd->cell_reversed) d->add_cell_reversed(reversed);
    for (bool mirrored : bd->cell_mirrored) d->add_cell_mirrored(mirrored);
  }
  for (const ChargeCycle& c : plan.cycles) {
    v1::ChargeCycle* o = out->add_cycles();
    o->set_first_waypoint(c.first_waypoint);
    o->set_last_waypoint(c.last_waypoint);
    o->set_resume_waypoint(c.resume_waypoint);
    o->set_leave_waypoint(c.leave_waypoint);
    o->set_energy(c.energy);
    o->set_energy_at_leave(c.energy_at_leave);
    if (c.resume_waypoint >= 0 && c.resume_waypoint < static_cast<int>(plan.path.size())) {
      const Waypoint& w = plan.path[c.resume_waypoint];
      o->mutable_resume()->set_x(w.x);
      o->mutable_resume()->set_y(w.y);
      o->mutable_resume()->set_theta(w.theta);
    }
    o->set_resume_unit(c.resume_unit);
    o->set_resumes_mid_unit(c.resumes_mid_unit);
  }
  if (const StcDetail* stc = plan.detail_as<StcDetail>())
    StcDetailToProto(*stc, out->mutable_stc());
  for (const Waypoint& w : plan.path) {
    v1::Waypoint* p = out->add_path();
    p->set_x(w.x);
    p->set_y(w.y);
    p->set_theta(w.theta);
    p->set_kind(KindToProto(w.kind));
    p->set_rank(w.rank);
  }
  const int cols = plan.grid != nullptr ? plan.grid->cols() : 0;
  for (const CoverageSweep& sweep : plan.sweeps) {
    v1::CoverageSweep* s = out->add_sweeps();
    s->set_waypoint(sweep.waypoint);
    for (const CellIndex& c : sweep.cells) s->add_cells(c.row * cols + c.col);
  }
  TerminationToProto(plan.termination, out->mutable_termination());
  const PlanStats& s = plan.stats;
  v1::PlanStats* o = out->mutable_stats();
  o->set_num_ranks(static_cast<int32_t>(s.num_ranks));
  o->set_num_turns(static_cast<int32_t>(s.num_turns));
  o->set_coverage_length_m(s.coverage_length_m);
  o->set_transition_length_m(s.transition_length_m);
  o->set_covered_free_area_ratio(s.covered_free_area_ratio);
  o->set_estimated_duration_s(s.estimated_duration_s);
  o->set_turning_time_s(s.turning_time_s);
  o->set_planning_ms(s.planning_ms);
  o->set_grid_ms(s.grid_ms);
  o->set_partition_ms(s.partition_ms);
  o->set_transitions_ms(s.transitions_ms);
  o->set_tour_ms(s.tour_ms);
  o->set_free_cells(static_cast<int32_t>(s.free_cells));
  o->set_grid_rows(static_cast<int32_t>(s.grid_rows));
  o->set_grid_cols(static_cast<int32_t>(s.grid_cols));
  o->set_map_free_area_m2(s.map_free_area_m2);
  o->set_reachable_area_m2(s.reachable_area_m2);
  o->set_swept_reachable_ratio(s.swept_reachable_ratio);
  o->set_missed_reachable_m2(s.missed_reachable_m2);
  o->set_floor_ms(s.floor_ms);
  o->set_tour_cut_short(s.tour_cut_short);
  o->set_decomposition_cached(s.decomposition_cached);
  o->set_plan_source(PlanOriginToProto(s.plan_source));
  o->set_partition_solver(s.partition_solver);
  o->set_tour_solver(s.tour_solver);
  o->set_unreachable_free_cells(static_cast<int32_t>(s.unreachable_free_cells));
  o->set_covered_cells(static_cast<int32_t>(s.covered_cells));
  o->set_no_go_cells(static_cast<int32_t>(s.no_go_cells));
  o->set_mission_covered_cells(static_cast<int32_t>(s.mission_covered_cells));
  o->set_mission_cut_off_cells(static_cast<int32_t>(s.mission_cut_off_cells));
  o->set_mission_obstructed_cells(static_cast<int32_t>(s.mission_obstructed_cells));
  o->set_charge_cycles(static_cast<int32_t>(s.charge_cycles));
  o->set_energy_total(s.energy_total);
  o->set_energy_unconstrained(s.energy_unconstrained);
  o->set_energy_lower_bound(s.energy_lower_bound);
}

void RetainedPlanFieldsToProto(const RetainedPlan& retained, v1::PlanResponse* out) {
  out->set_plan_id(retained.plan_id);
  out->set_map_id(retained.map_id);
  PolygonsToProto(retained.request.regions, out->mutable_regions());
  PolygonsToProto(retained.request.no_go, out->mutable_no_go());
  const std::vector<double> times = ArrivalTimes(retained.request.common.robot, retained.plan.path);
  for (int i = 0; i < out->path_size() && i < static_cast<int>(times.size()); ++i)
    out->mutable_path(i)->set_time_s(times[i]);
}

void RetainedPlanToProto(const RetainedPlan& retained, v1::PlanResponse* out) {
  PlanToProto(retained.plan, out);
  RetainedPlanFieldsToProto(retained, out);
}

absl::StatusOr<CoveragePlan> PlanFromProto(const v1::PlanResponse& response) {
  CoveragePlan plan;
  ASSIGN_OR_RETURN(plan.grid, GridFromProto(response.grid()));
  plan.planner = response.planner();
  ASSIGN_OR_RETURN(plan.detail, OarpDetailFromProto(response, *plan.grid));
  if (response.has_boustrophedon()) {
    ASSIGN_OR_RETURN(plan.detail,
                     BoustrophedonDetailFromProto(response.boustrophedon(), *plan.grid));
  }
  if (response.has_stc()) {
    ASSIGN_OR_RETURN(plan.detail, StcDetailFromProto(response.stc()));
  }
  RETURN_IF_ERROR(PathFromProto(response, &plan));
  plan.termination = TerminationFromProto(response.termination());
  plan.stats = PlanStatsFromProto(response.stats());
  ASSIGN_OR_RETURN(plan.cycles, CyclesFromProto(response, static_cast<int>(plan.path.size())));
  return plan;
}

absl::StatusOr<std::string> PlanToJson(const v1::PlanResponse& response) {
  return ProtoToJson(response);
}

absl::StatusOr<std::string> ProtoToJson(const google::protobuf::Message& response) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(response, &json, options);
  if (!status.ok()) {
    return absl::InternalError(
        absl::StrCat("cannot print ", response.GetTypeName(), " as JSON: ", status.ToString()));
  }
  return json;
}

}  // namespace covplan
