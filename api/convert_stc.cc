#include "api/convert_stc.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

absl::StatusOr<StcTreeMethod> TreeFromProto(v1::StcTree t, const char* field) {
  switch (t) {
    case v1::STC_TREE_UNSPECIFIED:
    case v1::STC_TREE_DFS:
      return StcTreeMethod::kDfs;
    case v1::STC_TREE_PRIM:
      return StcTreeMethod::kPrim;
    default:
      return absl::InvalidArgumentError(absl::StrCat(field, ": unknown value ", static_cast<int>(t),
                                                     " (STC_TREE_DFS or STC_TREE_PRIM)"));
  }
}

absl::StatusOr<SweepDirection> DirectionFromProto(v1::StcSweepDirection d, const char* field) {
  switch (d) {
    case v1::STC_SWEEP_DIRECTION_UNSPECIFIED:
    case v1::STC_SWEEP_HORIZONTAL:
      return SweepDirection::kHorizontal;
    case v1::STC_SWEEP_VERTICAL:
      return SweepDirection::kVertical;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat(field, ": unknown value ", static_cast<int>(d),
                       " (STC_SWEEP_HORIZONTAL or STC_SWEEP_VERTICAL)"));
  }
}

absl::StatusOr<PartialCells> PartialFromProto(v1::StcPartialCells p, const char* field) {
  switch (p) {
    case v1::STC_PARTIAL_CELLS_UNSPECIFIED:
    case v1::STC_PARTIAL_COVER:
      return PartialCells::kCover;
    case v1::STC_PARTIAL_DISCARD:
      return PartialCells::kDiscard;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat(field, ": unknown value ", static_cast<int>(p),
                       " (STC_PARTIAL_COVER or STC_PARTIAL_DISCARD)"));
  }
}

v1::StcTree TreeToProto(StcTreeMethod t) {
  return t == StcTreeMethod::kPrim ? v1::STC_TREE_PRIM : v1::STC_TREE_DFS;
}
v1::StcSweepDirection DirectionToProto(SweepDirection d) {
  return d == SweepDirection::kVertical ? v1::STC_SWEEP_VERTICAL : v1::STC_SWEEP_HORIZONTAL;
}
v1::StcPartialCells PartialToProto(PartialCells p) {
  return p == PartialCells::kDiscard ? v1::STC_PARTIAL_DISCARD : v1::STC_PARTIAL_COVER;
}

}  // namespace

absl::StatusOr<std::shared_ptr<const StcOptions>> StcOptionsFromProto(
    const v1::StcOptions& options) {
  auto out = std::make_shared<StcOptions>();
  ASSIGN_OR_RETURN(out->tree, TreeFromProto(options.tree(), "stc.tree"));
  ASSIGN_OR_RETURN(out->sweep_direction,
                   DirectionFromProto(options.sweep_direction(), "stc.sweep_direction"));
  ASSIGN_OR_RETURN(out->partial_cells,
                   PartialFromProto(options.partial_cells(), "stc.partial_cells"));
  RETURN_IF_ERROR(out->Validate());
  return std::shared_ptr<const StcOptions>(std::move(out));
}

void StcDetailToProto(const StcDetail& d, v1::StcDetail* out) {
  out->set_tree(TreeToProto(d.tree));
  out->set_sweep_direction(DirectionToProto(d.sweep_direction));
  out->set_partial_cells(PartialToProto(d.partial_cells));
  out->set_offset_row(d.offset.row);
  out->set_offset_col(d.offset.col);
  out->set_coarse_cells(static_cast<int32_t>(d.coarse_cells));
  out->set_full_coarse_cells(static_cast<int32_t>(d.full_coarse_cells));
  out->set_partial_coarse_cells(static_cast<int32_t>(d.partial_coarse_cells));
  out->set_tree_edges(static_cast<int32_t>(d.tree_edges));
  out->set_trees(static_cast<int32_t>(d.trees));
  out->set_extra_moves(static_cast<int32_t>(d.extra_moves));
  out->set_subcells_covered_twice(static_cast<int32_t>(d.subcells_covered_twice));
  out->set_discarded_cells(static_cast<int32_t>(d.discarded_cells));
  out->set_orphan_cells(static_cast<int32_t>(d.orphan_cells));
}

absl::StatusOr<std::shared_ptr<const StcDetail>> StcDetailFromProto(const v1::StcDetail& p) {
  auto d = std::make_shared<StcDetail>();
  ASSIGN_OR_RETURN(d->tree, TreeFromProto(p.tree(), "stc.tree"));
  ASSIGN_OR_RETURN(d->sweep_direction,
                   DirectionFromProto(p.sweep_direction(), "stc.sweep_direction"));
  ASSIGN_OR_RETURN(d->partial_cells, PartialFromProto(p.partial_cells(), "stc.partial_cells"));
  if (p.offset_row() < 0 || p.offset_row() > 1 || p.offset_col() < 0 || p.offset_col() > 1) {
    return absl::InvalidArgumentError("stc.offset_row / stc.offset_col must be 0 or 1");
  }
  d->offset = {p.offset_row(), p.offset_col()};
  d->coarse_cells = p.coarse_cells();
  d->full_coarse_cells = p.full_coarse_cells();
  d->partial_coarse_cells = p.partial_coarse_cells();
  d->tree_edges = p.tree_edges();
  d->trees = p.trees();
  d->extra_moves = p.extra_moves();
  d->subcells_covered_twice = p.subcells_covered_twice();
  d->discarded_cells = p.discarded_cells();
  d->orphan_cells = p.orphan_cells();
  return std::shared_ptr<const StcDetail>(std::move(d));
}

}  // namespace covplan
