// The plan half of the proto edge (convert.h): CoveragePlan <-> PlanResponse
// and the canonical JSON of plan.json.
#include "server/convert.h"

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "google/protobuf/util/json_util.h"
#include "planner/grid/grid.h"
#include "planner/partition/rank.h"

namespace covplan {

void PlanToProto(const CoveragePlan& plan, v1::PlanResponse* out) {
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
  for (const Rank& rank : plan.ranks) {
    v1::Rank* r = out->add_ranks();
    r->set_orientation(rank.orientation == Orientation::kHorizontal ? v1::HORIZONTAL
                                                                    : v1::VERTICAL);
    r->mutable_first_cell()->set_row(rank.first.row);
    r->mutable_first_cell()->set_col(rank.first.col);
    r->mutable_last_cell()->set_row(rank.last.row);
    r->mutable_last_cell()->set_col(rank.last.col);
  }
  for (int index : plan.rank_order) out->add_rank_order(index);
  for (bool reversed : plan.rank_reversed) out->add_rank_reversed(reversed);
  for (const Waypoint& w : plan.path) {
    v1::Waypoint* p = out->add_path();
    p->set_x(w.x);
    p->set_y(w.y);
    p->set_theta(w.theta);
    switch (w.kind) {
      case SegmentKind::kStart: p->set_kind(v1::START); break;
      case SegmentKind::kCoverage: p->set_kind(v1::COVERAGE); break;
      case SegmentKind::kTransition: p->set_kind(v1::TRANSITION); break;
    }
    p->set_rank(w.rank);
  }
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
  o->set_tour_cut_short(s.tour_cut_short);
  o->set_decomposition_cached(s.decomposition_cached);
  o->set_partition_solver(s.partition_solver);
  o->set_tour_solver(s.tour_solver);
  o->set_unreachable_free_cells(static_cast<int32_t>(s.unreachable_free_cells));
}

absl::StatusOr<CoveragePlan> PlanFromProto(const v1::PlanResponse& response) {
  const v1::Grid& g = response.grid();
  if (g.rows() <= 0 || g.cols() <= 0 || g.free_cells_size() != g.rows()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "plan grid is inconsistent: %d rows x %d cols with %d row strings", g.rows(), g.cols(),
        g.free_cells_size()));
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
  CoveragePlan plan;
  plan.grid = std::make_shared<const Grid>(g.rows(), g.cols(), g.cell_size_m(),
                                           Point2{g.origin_x_m(), g.origin_y_m()}, std::move(free));
  for (const v1::Rank& r : response.ranks()) {
    Rank rank;
    if (r.orientation() != v1::HORIZONTAL && r.orientation() != v1::VERTICAL) {
      return absl::InvalidArgumentError("plan rank has no orientation");
    }
    rank.orientation = r.orientation() == v1::HORIZONTAL ? Orientation::kHorizontal
                                                         : Orientation::kVertical;
    rank.first = {r.first_cell().row(), r.first_cell().col()};
    rank.last = {r.last_cell().row(), r.last_cell().col()};
    if (!plan.grid->InBounds(rank.first.row, rank.first.col) ||
        !plan.grid->InBounds(rank.last.row, rank.last.col)) {
      return absl::InvalidArgumentError("plan rank lies outside the grid");
    }
    plan.ranks.push_back(rank);
  }
  for (int32_t index : response.rank_order()) {
    if (index < 0 || index >= static_cast<int>(plan.ranks.size())) {
      return absl::InvalidArgumentError("plan rank_order refers to a missing rank");
    }
    plan.rank_order.push_back(index);
  }
  plan.rank_reversed.assign(response.rank_reversed().begin(), response.rank_reversed().end());
  for (const v1::Waypoint& p : response.path()) {
    Waypoint w;
    w.x = p.x();
    w.y = p.y();
    w.theta = p.theta();
    w.kind = p.kind() == v1::COVERAGE     ? SegmentKind::kCoverage
             : p.kind() == v1::TRANSITION ? SegmentKind::kTransition
                                          : SegmentKind::kStart;
    w.rank = p.rank();
    plan.path.push_back(w);
  }
  const v1::PlanStats& s = response.stats();
  PlanStats& o = plan.stats;
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
  o.tour_cut_short = s.tour_cut_short();
  o.decomposition_cached = s.decomposition_cached();
  o.partition_solver = s.partition_solver();
  o.tour_solver = s.tour_solver();
  o.unreachable_free_cells = s.unreachable_free_cells();
  return plan;
}

absl::StatusOr<std::string> PlanToJson(const v1::PlanResponse& response) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(response, &json, options);
  if (!status.ok()) {
    return absl::InternalError(absl::StrCat("cannot print plan as JSON: ", status.ToString()));
  }
  return json;
}

}  // namespace covplan
