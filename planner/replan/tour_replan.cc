#include "planner/replan/tour_replan.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <tuple>
#include <utility>

#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/tour/polyline_tour.h"
#include "planner/tour/tour_model.h"

namespace covplan::replan_internal {
namespace {

// Elements of TOUR-REPLAN for a new partition `ranks` (with is_new flags):
// the maximal unchanged sections of the old path after `walk` stopped whose
// coverage segments are all kept ranks, and every other rank on its own.
std::vector<PolylineElement> TourElements(const Remainder& rest, const Walk& walk,
                                          const std::vector<Rank>& ranks,
                                          const std::vector<bool>& is_new, ReplanStats* stats) {
  const Grid& drive = *rest.drive;
  const CoveragePlan& old = rest.old->plan;
  std::map<std::tuple<int, int, int, int, int>, int> kept;  // rank -> index in `ranks`
  for (size_t r = 0; r < ranks.size(); ++r) {
    if (is_new[r]) continue;
    const Rank& k = ranks[r];
    kept[{static_cast<int>(k.orientation), k.first.row, k.first.col, k.last.row, k.last.col}] =
        static_cast<int>(r);
  }
  auto kept_index = [&](int old_segment) -> int {
    const int tag = old.path[old_segment].rank;
    if (rest.old_oarp == nullptr || tag < 0 || tag >= static_cast<int>(rest.old_oarp->ranks.size()))
      return -1;
    const Rank& k = rest.old_oarp->ranks[tag];
    auto it = kept.find(
        {static_cast<int>(k.orientation), k.first.row, k.first.col, k.last.row, k.last.col});
    return it == kept.end() ? -1 : it->second;
  };
  const Grid& old_drive = *rest.old->area->drive;
  auto closed = [&](int r, int col) { return NewlyClosed(old_drive, drive, r, col); };
  auto segment_clear = [&](int i) {
    const Waypoint& a = old.path[i - 1];
    const Waypoint& b = old.path[i];
    return !SegmentTouches(drive, {a.x, a.y}, {b.x, b.y}, closed);
  };
  std::vector<bool> used(ranks.size(), false);
  std::vector<PolylineElement> elements;
  std::map<int, const CoverageSweep*> sweep_at;
  for (const CoverageSweep& s : old.sweeps) sweep_at[s.waypoint] = &s;
  // Old segments strictly after the leg the walk stopped on.
  const int first = walk.end_leg >= 0 && walk.end_leg < static_cast<int>(rest.legs.size())
                        ? rest.legs[walk.end_leg].old_segment + 1
                        : static_cast<int>(old.path.size());
  PolylineElement piece;
  int last_coverage = -1;  // number of segments in `piece` up to its last kept coverage segment
  auto close_piece = [&] {
    if (last_coverage > 0) {
      piece.points.resize(last_coverage + 1);
      piece.kinds.resize(last_coverage);
      piece.sweeps.resize(last_coverage);
      piece.tags.resize(last_coverage);
      piece.last_cell = drive.CellAt(piece.points.back());
      piece.kind = TourElementKind::kPathPiece;
      double len = 0;
      for (size_t k = 1; k < piece.points.size(); ++k) {
        len += std::hypot(piece.points[k].x - piece.points[k - 1].x,
                          piece.points[k].y - piece.points[k - 1].y);
      }
      ++stats->kept_path_pieces;
      stats->kept_path_m += len;
      elements.push_back(std::move(piece));
    }
    piece = PolylineElement();
    last_coverage = -1;
  };
  for (int i = first; i < static_cast<int>(old.path.size()); ++i) {
    const Waypoint& wb = old.path[i];
    const bool coverage = wb.kind == SegmentKind::kCoverage;
    const int r = coverage ? kept_index(i) : -1;
    const bool usable = segment_clear(i) && (!coverage || (r >= 0 && !used[r]));
    if (!usable || (piece.points.empty() && !coverage)) {
      close_piece();
      continue;
    }
    if (piece.points.empty()) {
      const Waypoint& wa = old.path[i - 1];
      piece.points.push_back({wa.x, wa.y});
      piece.first_cell = drive.CellAt({wa.x, wa.y});
    }
    piece.points.push_back({wb.x, wb.y});
    piece.kinds.push_back(wb.kind);
    auto sw = sweep_at.find(i);
    piece.sweeps.push_back(coverage && sw != sweep_at.end() ? sw->second->cells
                                                            : std::vector<CellIndex>{});
    piece.tags.push_back(coverage ? r : -1);
    if (coverage) {
      used[r] = true;
      last_coverage = static_cast<int>(piece.kinds.size());
    }
  }
  close_piece();
  for (size_t r = 0; r < ranks.size(); ++r) {
    if (used[r]) continue;
    elements.push_back(RankElement(drive, ranks[r].first, ranks[r].last, static_cast<int>(r)));
  }
  return elements;
}

// Joins the walk's prefix (robot -> tour start) and the tour path.
void Append(const std::vector<Waypoint>& tour, const std::vector<CoverageSweep>& tour_sweeps,
            CoveragePlan* plan) {
  const int offset = static_cast<int>(plan->path.size()) - 1;  // tour[0] is the prefix's end
  for (size_t i = 1; i < tour.size(); ++i) plan->path.push_back(tour[i]);
  for (const CoverageSweep& s : tour_sweeps) plan->sweeps.push_back({s.waypoint + offset, s.cells});
}

}  // namespace

absl::StatusOr<bool> TourReplan(const Remainder& rest, const Walk& walk,
                                const std::vector<Rank>& ranks, const std::vector<bool>& is_new,
                                const ReplanOptions& options, const StopToken& stop,
                                double tour_budget_s, ReplanResult* out) {
  std::vector<PolylineElement> elements = TourElements(rest, walk, ranks, is_new, &out->stats);
  if (elements.empty()) {
    // Nothing left to cover after the prefix: drive on to the old end.
    ASSIGN_OR_RETURN(bool routed,
                     AppendRoute(*rest.drive, walk.end, rest.end, stop, &out->plan.path));
    if (!routed) return false;
    out->plan.termination = Termination::Converged("nothing left to cover: drive to the end");
    return true;
  }
  const absl::Time t0 = absl::Now();
  absl::StatusOr<PolylineTourModel> model = PolylineTourModel::Create(
      *rest.drive, std::move(elements), Pose2{walk.end.x, walk.end.y, walk.end_heading}, rest.end,
      std::make_shared<const TravelTimeCost>(rest.robot), stop, options.num_threads);
  if (!model.ok()) {
    if (absl::IsDeadlineExceeded(model.status()) || absl::IsCancelled(model.status())) return false;
    return model.status();
  }
  out->stats.transitions_ms = model->transitions_ms();
  const absl::Time t1 = absl::Now();
  OrdererOptions oo;
  oo.time_limit_s = std::max(
      1e-3, std::min(options.tour_time_limit_s, tour_budget_s - absl::ToDoubleSeconds(t1 - t0)));
  oo.seed = options.seed;
  oo.num_threads = options.num_threads;
  absl::StatusOr<TourOrder> order = GtspOrderer(oo).Order(*model, stop);
  if (!order.ok()) {
    if (absl::IsDeadlineExceeded(order.status()) || absl::IsCancelled(order.status())) return false;
    return order.status();
  }
  out->stats.tour_ms = absl::ToDoubleMilliseconds(absl::Now() - t1);
  std::vector<Waypoint> tour;
  std::vector<CoverageSweep> sweeps;
  model->BuildPath(order->vertices, &tour, &sweeps);
  Append(tour, sweeps, &out->plan);
  out->plan.termination = order->termination;
  return true;
}

}  // namespace covplan::replan_internal
