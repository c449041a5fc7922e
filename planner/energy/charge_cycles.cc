#include "planner/energy/charge_cycles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "planner/common/status_macros.h"
#include "planner/energy/charge_split.h"
#include "planner/tour/grid_paths.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

const char* UnitWord(const std::string& planner) {
  if (planner == "oarp") return "rank";
  if (planner == "boustrophedon") return "cell";
  return "unit";
}

struct Piece {
  int a = 0;  // waypoint where the piece starts (the robot arrives here)
  int z = 0;  // waypoint where it ends (a charge may follow)
  int unit = 0;
  int line = 0;  // index of the piece within its unit
};

// Legs between the station and points of the plan, on the drive grid.
class StationLegs {
 public:
  StationLegs(const Grid& drive, const BatteryOptions& battery)
      : drive_(drive), battery_(battery), search_(drive) {}

  absl::Status Run(const StopToken& stop) {
    ASSIGN_OR_RETURN(station_cell_, JoinCell(drive_, battery_.station, "battery.station"));
    if (!search_.Run(station_cell_, stop))
      return absl::DeadlineExceededError("stopped while routing from the station");
    return absl::OkStatus();
  }
  // Points station -> p; nullopt when p cannot be reached.
  std::optional<std::vector<Point2>> Points(Point2 p) const {
    const CellIndex c = drive_.CellAt(p);
    if (!drive_.InBounds(c.row, c.col) || !search_.Reached(c)) return std::nullopt;
    std::vector<Point2> pts = {{battery_.station.x, battery_.station.y}};
    for (const CellIndex& k : search_.PathTo(c)) pts.push_back(drive_.CellCenter(k));
    pts.push_back(p);
    return pts;
  }
  // Waypoints after `from` along `pts` (pts[0] is at `from`), kind `kind`.
  static void Append(const std::vector<Point2>& pts, SegmentKind kind, std::vector<Waypoint>* out) {
    Point2 at = pts.front();
    for (size_t i = 1; i < pts.size(); ++i) {
      const double dx = pts[i].x - at.x, dy = pts[i].y - at.y;
      if (std::hypot(dx, dy) < kMinSegmentM) continue;
      out->push_back({pts[i].x, pts[i].y, std::atan2(dy, dx), kind, -1});
      at = pts[i];
    }
  }
  // Outbound leg along `pts`: its waypoints after the station's.
  std::vector<Waypoint> Out(const std::vector<Point2>& pts) const {
    std::vector<Waypoint> w;
    Append(pts, SegmentKind::kFromStation, &w);
    return w;
  }
  // Return leg along `pts` reversed, ending with the turn onto the
  // station's heading.
  std::vector<Waypoint> Back(std::vector<Point2> pts) const {
    std::reverse(pts.begin(), pts.end());
    std::vector<Waypoint> w;
    Append(pts, SegmentKind::kToStation, &w);
    w.push_back({battery_.station.x, battery_.station.y, battery_.station.theta,
                 SegmentKind::kToStation, -1});
    return w;
  }
  Waypoint StationWaypoint(SegmentKind kind) const {
    return {battery_.station.x, battery_.station.y, battery_.station.theta, kind, -1};
  }

 private:
  const Grid& drive_;
  const BatteryOptions& battery_;
  AnyAngleSearch search_;
  CellIndex station_cell_;
};

// Energy of `legs` driven from `start` (its heading included).
double LegEnergy(const Waypoint& start, const std::vector<Waypoint>& legs, const EnergyModel& m,
                 const RobotModel& robot) {
  double e = 0.0;
  const Waypoint* prev = &start;
  for (const Waypoint& w : legs) {
    e += SegmentEnergy(prev->theta, *prev, w, m, robot);
    prev = &w;
  }
  return e;
}

// The plan's coverage cut into pieces a charge may fall between: each unit
// (a run of coverage segments with one tag, in path order) is one piece when
// atomic, else one piece per segment.
struct Pieces {
  std::vector<Piece> pieces;
  std::vector<int> unit_tag;  // per unit

  // "rank 3", or "line 2 of rank 3" for a piece of an interruptible unit.
  std::string Name(int k, const std::string& planner, const BatteryOptions& battery) const {
    const Piece& p = pieces[k];
    const std::string unit = absl::StrFormat("%s %d", UnitWord(planner), unit_tag[p.unit]);
    return battery.IsAtomic(unit_tag[p.unit]) ? unit
                                              : absl::StrFormat("line %d of %s", p.line, unit);
  }
};

Pieces CutIntoPieces(const std::vector<Waypoint>& path, const BatteryOptions& battery) {
  Pieces out;
  std::vector<Piece>& pieces = out.pieces;
  int prev_cov = -1;
  for (int i = 1; i < static_cast<int>(path.size()); ++i) {
    if (path[i].kind != SegmentKind::kCoverage) continue;
    const bool same_unit =
        prev_cov >= 0 && path[i].rank >= 0 && path[prev_cov].rank == path[i].rank;
    if (!same_unit) {
      out.unit_tag.push_back(path[i].rank);
      pieces.push_back({i - 1, i, static_cast<int>(out.unit_tag.size()) - 1, 0});
    } else if (!battery.IsAtomic(path[i].rank)) {
      pieces.push_back({pieces.back().z, i, pieces.back().unit, pieces.back().line + 1});
    } else {
      pieces.back().z = i;
    }
    prev_cov = i;
  }
  return out;
}

// The energies the split chooses among: per piece, the leg out to it, its
// own work and the leg back; between pieces, the plan's own link. A piece
// that cannot be reached, or cannot be covered on one charge, is
// InvalidArgument. Piece k's first segment is priced in out[k] (after a
// charge) or in link[k - 1] (along the tour); work[k] starts after it.
absl::StatusOr<SplitProblem> PriceSplit(const CoveragePlan& plan, const Pieces& units,
                                        const StationLegs& legs, const BatteryOptions& battery,
                                        const RobotModel& robot, const StopToken& stop) {
  const std::vector<Waypoint>& path = plan.path;
  const std::vector<Piece>& pieces = units.pieces;
  const EnergyModel& model = battery.energy;
  const Waypoint station = legs.StationWaypoint(SegmentKind::kStart);
  const int n = static_cast<int>(pieces.size());
  // seg + turn energy of the segment ending at waypoint t, after t - 1.
  auto step = [&](int t) {
    return SegmentEnergy(path[t - 1].theta, path[t - 1], path[t], model, robot);
  };
  SplitProblem sp;
  sp.out.resize(n), sp.work.resize(n), sp.back.resize(n), sp.link.resize(n > 0 ? n - 1 : 0);
  for (int k = 0; k < n; ++k) {
    if (k % 64 == 0 && stop.ShouldStop())
      return absl::DeadlineExceededError("stopped while pricing charge cycles");
    const Piece& p = pieces[k];
    const Point2 pa{path[p.a].x, path[p.a].y}, pz{path[p.z].x, path[p.z].y};
    std::optional<std::vector<Point2>> to_a = legs.Points(pa), to_z = legs.Points(pz);
    if (!to_a || !to_z) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "battery.station (%.3f, %.3f) cannot reach %s on the drive grid", battery.station.x,
          battery.station.y, units.Name(k, plan.planner, battery)));
    }
    const std::vector<Waypoint> out = legs.Out(*to_a);
    const Waypoint& arrive = out.empty() ? station : out.back();
    // The piece's first segment, entered from the leg's heading.
    sp.out[k] = LegEnergy(station, out, model, robot) +
                SegmentEnergy(arrive.theta, path[p.a], path[p.a + 1], model, robot);
    double work = 0.0;
    for (int t = p.a + 2; t <= p.z; ++t) work += step(t);
    sp.work[k] = work;
    sp.back[k] = LegEnergy(path[p.z], legs.Back(*to_z), model, robot);
    if (k + 1 < n) {
      double link = 0.0;
      for (int t = p.z + 1; t <= pieces[k + 1].a + 1; ++t) link += step(t);
      sp.link[k] = link;
    }
    const double solo = CycleEnergy(sp, k, k);
    if (solo > battery.budget()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("battery: %s needs %.6g to reach from the station, cover and return, "
                          "above capacity - reserve = %.6g",
                          units.Name(k, plan.planner, battery), solo, battery.budget()));
    }
  }
  return sp;
}

// `plan` driven as the cycles of `split`: from the station, out to each
// cycle's first piece, along the plan to its last and back; the sweeps
// renumbered onto the new path. Internal when a cycle does not drive the
// energy the split priced.
absl::StatusOr<CoveragePlan> DriveCycles(const CoveragePlan& plan, const Pieces& units,
                                         const StationLegs& legs, const SplitResult& split,
                                         const BatteryOptions& battery, const RobotModel& robot) {
  const std::vector<Waypoint>& path = plan.path;
  const std::vector<Piece>& pieces = units.pieces;
  const EnergyModel& model = battery.energy;
  CoveragePlan out = plan;
  out.path.clear();
  out.sweeps.clear();
  out.cycles.clear();
  std::vector<int> new_index(path.size(), -1);
  out.path.push_back(legs.StationWaypoint(SegmentKind::kStart));
  for (size_t c = 0; c < split.cycles.size(); ++c) {
    const auto [i, j] = split.cycles[c];
    ChargeCycle cycle;
    cycle.first_waypoint = static_cast<int>(out.path.size()) - 1;
    const Piece& first = pieces[i];
    const Piece& last = pieces[j];
    for (const Waypoint& w : legs.Out(*legs.Points({path[first.a].x, path[first.a].y})))
      out.path.push_back(w);
    cycle.resume_waypoint = static_cast<int>(out.path.size()) - 1;
    cycle.resume_unit = units.unit_tag[first.unit];
    cycle.resumes_mid_unit = i > 0 && pieces[i - 1].unit == first.unit;
    for (int t = first.a + 1; t <= last.z; ++t) {
      new_index[t] = static_cast<int>(out.path.size());
      out.path.push_back(path[t]);
    }
    cycle.leave_waypoint = static_cast<int>(out.path.size()) - 1;
    for (const Waypoint& w : legs.Back(*legs.Points({path[last.z].x, path[last.z].y})))
      out.path.push_back(w);
    cycle.last_waypoint = static_cast<int>(out.path.size()) - 1;
    cycle.energy = PathEnergy(out.path, cycle.first_waypoint, cycle.last_waypoint, model, robot);
    cycle.energy_at_leave =
        PathEnergy(out.path, cycle.first_waypoint, cycle.leave_waypoint, model, robot);
    if (cycle.energy > battery.budget() * (1 + 1e-9) + 1e-9 ||
        std::abs(cycle.energy - split.energy[c]) > 1e-6 * std::max(1.0, cycle.energy)) {
      return absl::InternalError(absl::StrFormat("battery split: cycle %d priced %g, drives %g", c,
                                                 split.energy[c], cycle.energy));
    }
    out.cycles.push_back(cycle);
  }
  for (const CoverageSweep& s : plan.sweeps) {
    if (new_index[s.waypoint] < 0)
      return absl::InternalError("battery split dropped a coverage segment");
    out.sweeps.push_back({new_index[s.waypoint], s.cells});
  }
  return out;
}

// A lower bound on the energy of any split of `sp` within `budget`, given
// the energy `unconstrained` of driving it on one charge.
// A charge after piece k replaces link[k] by back[k] + out[k + 1], which
// costs delta[k] more (negative when the plan's own move between the two
// pieces is longer than the way through the station, e.g. STC's walk).
// Any split with visits S costs E_u + sum of delta over S; it cannot cost
// less than E_u + every negative delta, so it needs at least
// c = ceil(that / budget) - 1 visits; the cheapest c visits are all the
// negative ones and then the smallest others.
double EnergyLowerBound(const SplitProblem& sp, double unconstrained, double budget) {
  const int n = sp.size();
  std::vector<double> delta;
  for (int k = 0; k + 1 < n; ++k) delta.push_back(sp.back[k] + sp.out[k + 1] - sp.link[k]);
  std::sort(delta.begin(), delta.end());
  double floor_energy = unconstrained;
  size_t negative = 0;
  for (; negative < delta.size() && delta[negative] < 0; ++negative)
    floor_energy += delta[negative];
  const double visits = std::max(0.0, std::ceil(floor_energy / budget - 1e-12) - 1);
  double bound = floor_energy;
  for (size_t k = negative; k < delta.size() && static_cast<double>(k) < visits; ++k)
    bound += delta[k];
  return bound;
}

}  // namespace

absl::Status CheckStation(const Grid& drive, const BatteryOptions& battery) {
  const Pose2& s = battery.station;
  const Point2 lo = drive.origin();
  const Point2 hi{lo.x + drive.cols() * drive.cell_size(), lo.y + drive.rows() * drive.cell_size()};
  if (s.x < lo.x || s.y < lo.y || s.x > hi.x || s.y > hi.y) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "battery.station (%.3f, %.3f) lies outside the map (%.3f, %.3f)..(%.3f, %.3f)", s.x, s.y,
        lo.x, lo.y, hi.x, hi.y));
  }
  const Point2 local{(s.x - lo.x) / drive.cell_size(), (s.y - lo.y) / drive.cell_size()};
  const CellIndex cell = drive.CellAt({s.x, s.y});
  const bool in_obstacle = drive.obstacle_pixels() != nullptr
                               ? drive.obstacle_pixels()->SegmentBlocked(local, local)
                               : !drive.IsFree(cell);
  if (in_obstacle) {
    return absl::InvalidArgumentError(
        absl::StrFormat("battery.station (%.3f, %.3f) lies in an obstacle", s.x, s.y));
  }
  absl::StatusOr<CellIndex> join = JoinCell(drive, s, "battery.station");
  if (!join.ok()) return join.status();
  return absl::OkStatus();
}

absl::StatusOr<CoveragePlan> SplitIntoChargeCycles(const CoveragePlan& plan, const Grid& drive,
                                                   const BatteryOptions& battery,
                                                   const RobotModel& robot, const StopToken& stop) {
  RETURN_IF_ERROR(battery.Validate());
  RETURN_IF_ERROR(CheckStation(drive, battery));
  const Pieces units = CutIntoPieces(plan.path, battery);
  if (units.pieces.empty())
    return absl::InvalidArgumentError("battery: the plan has nothing to cover");

  StationLegs legs(drive, battery);
  RETURN_IF_ERROR(legs.Run(stop));
  ASSIGN_OR_RETURN(const SplitProblem sp, PriceSplit(plan, units, legs, battery, robot, stop));
  absl::StatusOr<SplitResult> split = SplitTour(sp, battery.budget());
  if (!split.ok())
    return absl::InternalError(absl::StrCat("battery split: ", split.status().message()));

  ASSIGN_OR_RETURN(CoveragePlan out, DriveCycles(plan, units, legs, *split, battery, robot));
  PlanStats& st = out.stats;
  st.charge_cycles = static_cast<int64_t>(out.cycles.size());
  st.energy_total = split->total;
  st.energy_unconstrained = CycleEnergy(sp, 0, sp.size() - 1);
  st.energy_lower_bound = EnergyLowerBound(sp, st.energy_unconstrained, battery.budget());
  return out;
}

}  // namespace covplan
