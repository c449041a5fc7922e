#include "planner/sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/engine/engine.h"
#include "planner/sim/battery_run.h"
#include "planner/sim/clutter.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

Point2 Lerp(Point2 a, Point2 b, double t) { return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}; }
Point2 At(const Waypoint& w) { return {w.x, w.y}; }
double Dist(Point2 a, Point2 b) { return std::hypot(b.x - a.x, b.y - a.y); }

double Param(Point2 a, Point2 b, Point2 p) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  if (len2 <= 0.0) return 0.0;
  return std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0);
}

// Distance covered t seconds into a rest-to-rest straight of `length` m
// (the profile behind RobotModel::StraightTime).
double DistanceAt(const RobotModel& robot, double length, double t) {
  const double total = robot.StraightTime(length);
  if (t >= total) return length;
  if (t <= 0.0) return 0.0;
  const double a = robot.acceleration_mps2, v = robot.max_speed_mps;
  const double ramp_t = std::min(v / a, total / 2);  // accelerating, and braking at the end
  if (t <= ramp_t) return 0.5 * a * t * t;
  if (t >= total - ramp_t) return length - 0.5 * a * (total - t) * (total - t);
  return 0.5 * a * ramp_t * ramp_t + v * (t - ramp_t);
}

// Calls f(cell) for every grid cell whose interior the segment a -> b passes
// through, in order, until f returns true. Points on cell borders belong to
// no cell: a segment through a corner does not enter the two cells beside it,
// one along a border enters neither side.
template <typename F>
bool TraverseCells(const Grid& g, Point2 a, Point2 b, F f) {
  const double s = g.cell_size();
  const double x0 = (a.x - g.origin().x) / s, y0 = (a.y - g.origin().y) / s;
  const double dx = (b.x - a.x) / s, dy = (b.y - a.y) / s;
  constexpr double kEps = 1e-9;
  if (std::abs(dx) < kEps && std::abs(dy) < kEps) return false;
  auto on_line = [&](double v) { return std::abs(v - std::round(v)) < kEps; };
  if ((std::abs(dx) < kEps && on_line(x0)) || (std::abs(dy) < kEps && on_line(y0))) return false;
  auto first = [&](double v, double d) {
    return static_cast<int>(d > 0   ? std::floor(v + kEps)
                            : d < 0 ? std::ceil(v - kEps) - 1
                                    : std::floor(v));
  };
  int cx = first(x0, dx), cy = first(y0, dy);
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double step_x = std::abs(dx) >= kEps ? 1.0 / std::abs(dx) : kInf;
  const double step_y = std::abs(dy) >= kEps ? 1.0 / std::abs(dy) : kInf;
  double next_x = step_x < kInf ? (sx > 0 ? cx + 1 - x0 : x0 - cx) * step_x : kInf;
  double next_y = step_y < kInf ? (sy > 0 ? cy + 1 - y0 : y0 - cy) * step_y : kInf;
  for (int k = 0; k < 4 * (g.rows() + g.cols()) + 4; ++k) {
    if (f(CellIndex{cy, cx})) return true;
    const double next = std::min(next_x, next_y);
    if (next >= 1.0 - kEps) break;
    if (std::abs(next_x - next_y) < kEps) {  // through a corner: diagonally on
      cx += sx, cy += sy, next_x += step_x, next_y += step_y;
    } else if (next_x < next_y) {
      cx += sx, next_x += step_x;
    } else {
      cy += sy, next_y += step_y;
    }
  }
  return false;
}

// One run: the plan being driven, where the robot is on it, what it knows.
class Simulation {
 public:
  Simulation(const OccupancyMap& truth, const Grid& true_grid, const SimulationOptions& options,
             RetainedPlan plan, std::vector<uint8_t> candidate, PlanSource* source)
      : source_(source),
        truth_(truth),
        grid_(true_grid),
        options_(options),
        robot_(options.plan.robot),
        method_(options.plan.battery ? ReplanMethod::kGreedyDetour : options.method),
        plan_(std::move(plan)),
        candidate_(std::move(candidate)),
        found_(candidate_.size(), 0),
        pending_flag_(candidate_.size(), 0),
        reported_(candidate_.size(), 0),
        swept_(candidate_.size(), 0) {}

  absl::StatusOr<SimulationResult> Run();
  const std::vector<uint8_t>& swept() const { return swept_; }

 private:
  const std::vector<Waypoint>& path() const { return plan_.plan.path; }
  int64_t Index(CellIndex c) const { return grid_.Index(c.row, c.col); }
  bool Visible(Point2 from, CellIndex target) const;
  void Observe(CellIndex c);
  void Sense();
  // Calls f(sample) along the path still to drive until it returns true.
  template <typename F>
  bool ScanRemaining(F f) const;
  bool PendingOnPath() const;
  double TimeToFirstEntry(const std::vector<uint8_t>& flags) const;
  RobotProgress Progress() const;
  absl::Status DoReplan(ReplanMethod method);
  absl::Status HandleViolation(CellIndex cell);
  void PushDriven(const Waypoint& w);
  void IndexSweeps();
  // A problem line if `path` enters a cell already given to a replan.
  std::optional<std::string> CrossesReported(const std::vector<Waypoint>& path) const;

  PlanSource* const source_;
  const OccupancyMap& truth_;
  const Grid& grid_;  // the true grid (same frame as the plan's grid)
  const SimulationOptions& options_;
  const RobotModel robot_;
  // Battery plans keep their station legs only under the greedy detour.
  const ReplanMethod method_;
  RetainedPlan plan_;
  std::vector<uint8_t> candidate_;     // free on the planned drive grid, blocked on the true one
  std::vector<uint8_t> found_;         // candidates the robot has found
  std::vector<uint8_t> pending_flag_;  // found, not yet given to a replan
  std::vector<uint8_t> reported_;      // given to a replan
  std::vector<CellIndex> pending_;
  bool pending_checked_ = true;  // no pending cell added since PendingOnPath() said no
  std::vector<uint8_t> swept_;
  std::vector<int> sweep_of_;         // per waypoint: index into plan.sweeps or -1
  int seg_ = 1;                       // segment path[seg_-1] -> path[seg_] being driven
  double t_seg_ = 0.0, d_seg_ = 0.0;  // seconds / metres into it
  Point2 pos_;
  CellIndex here_;            // the cell the robot is in (borders are ambiguous)
  bool end_blocked_ = false;  // the plan's end pose lies in a blocked cell
  bool junction_ = false;     // driven.back() is where a replan cut a segment
  double drive_s_ = 0.0;      // rough drive time, for the time bound
  int violations_ = 0;
  SimulationResult r_;
};

// Line of sight over the true map's pixels (Amanatides-Woo traversal): no
// non-free pixel between the robot and the cell centre, except inside the
// target cell itself (the obstacle that blocks it) and the robot's own pixel.
bool Simulation::Visible(Point2 from, CellIndex target) const {
  const Point2 to = grid_.CellCenter(target);
  const double res = truth_.resolution();
  const double x0 = (from.x - truth_.origin().x) / res, y0 = (from.y - truth_.origin().y) / res;
  const double x1 = (to.x - truth_.origin().x) / res, y1 = (to.y - truth_.origin().y) / res;
  int cx = static_cast<int>(std::floor(x0)), cy = static_cast<int>(std::floor(y0));
  const int tx = static_cast<int>(std::floor(x1)), ty = static_cast<int>(std::floor(y1));
  const double dx = x1 - x0, dy = y1 - y0;
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double next_x = dx != 0 ? (sx > 0 ? cx + 1 - x0 : x0 - cx) / std::abs(dx) : kInf;
  double next_y = dy != 0 ? (sy > 0 ? cy + 1 - y0 : y0 - cy) / std::abs(dy) : kInf;
  const double step_x = dx != 0 ? 1.0 / std::abs(dx) : kInf,
               step_y = dy != 0 ? 1.0 / std::abs(dy) : kInf;
  const int max_steps = std::abs(tx - cx) + std::abs(ty - cy) + 2;
  for (int k = 0; k < max_steps && !(cx == tx && cy == ty); ++k) {
    if (next_x < next_y) {
      cx += sx, next_x += step_x;
    } else {
      cy += sy, next_y += step_y;
    }
    if (cx < 0 || cy < 0 || cx >= truth_.width() || cy >= truth_.height()) return false;
    if (truth_.IsFree(cy, cx)) continue;
    const Point2 centre{truth_.origin().x + (cx + 0.5) * res, truth_.origin().y + (cy + 0.5) * res};
    if (grid_.CellAt(centre) != target) return false;
  }
  return true;
}

void Simulation::Observe(CellIndex c) {
  const int64_t i = Index(c);
  if (found_[i]) return;
  found_[i] = pending_flag_[i] = 1;
  pending_.push_back(c);
  pending_checked_ = false;
  r_.obstacles_found.push_back(c);
}

void Simulation::Sense() {
  const double range = options_.sensor_range_m, s = grid_.cell_size();
  const CellIndex at = grid_.CellAt(pos_);
  const int reach = static_cast<int>(std::ceil(range / s)) + 1;
  for (int r = std::max(0, at.row - reach); r <= std::min(grid_.rows() - 1, at.row + reach); ++r) {
    for (int c = std::max(0, at.col - reach); c <= std::min(grid_.cols() - 1, at.col + reach);
         ++c) {
      const int64_t i = grid_.Index(r, c);
      if (!candidate_[i] || found_[i] || Dist(pos_, grid_.CellCenter(r, c)) > range) continue;
      if (Visible(pos_, {r, c})) Observe({r, c});
    }
  }
}

template <typename F>
bool Simulation::ScanRemaining(F f) const {
  const double step = grid_.cell_size() / 8.0;
  for (int i = seg_; i < static_cast<int>(path().size()); ++i) {
    const Point2 a = i == seg_ ? pos_ : At(path()[i - 1]), b = At(path()[i]);
    const int n = std::max(1, static_cast<int>(std::ceil(Dist(a, b) / step)));
    for (int k = 0; k <= n; ++k) {
      if (f(Lerp(a, b, static_cast<double>(k) / n), i, k, n)) return true;
    }
  }
  return false;
}

// Pending cells on the path still to drive or among the cells still to sweep.
bool Simulation::PendingOnPath() const {
  const bool on_path = ScanRemaining([&](Point2 p, int, int, int) {
    const CellIndex c = grid_.CellAt(p);
    return grid_.InBounds(c.row, c.col) && pending_flag_[Index(c)] != 0;
  });
  if (on_path) return true;
  for (const CoverageSweep& s : plan_.plan.sweeps) {
    if (s.waypoint < seg_) continue;
    for (const CellIndex& c : s.cells) {
      if (pending_flag_[Index(c)] && !swept_[Index(c)]) return true;
    }
  }
  return false;
}

// Drive time (robot model) from the robot to the first point where the path
// enters a flagged cell; infinity when it never does.
double Simulation::TimeToFirstEntry(const std::vector<uint8_t>& flags) const {
  double time = 0.0, last_d = 0.0;
  int last_segment = -1;
  bool hit = false;
  ScanRemaining([&](Point2 p, int i, int k, int n) {
    const Point2 a = i == seg_ ? pos_ : At(path()[i - 1]);
    if (i != last_segment) {
      if (last_segment >= 0) time += robot_.StraightTime(last_d);
      if (i != seg_ || d_seg_ <= 0.0)
        time += robot_.TurnTime(HeadingChange(path()[i - 1].theta, path()[i].theta));
      last_segment = i;
    }
    const CellIndex c = grid_.CellAt(p);
    if (grid_.InBounds(c.row, c.col) && flags[Index(c)]) return hit = true;
    last_d = Dist(a, p);
    return false;
  });
  if (!hit) return std::numeric_limits<double>::infinity();
  return time + robot_.StraightTime(last_d);
}

void Simulation::PushDriven(const Waypoint& w) {
  std::vector<Waypoint>& d = r_.driven;
  // A replan that continues straight on does not stop the robot.
  if (junction_ && d.size() >= 2 && d.back().kind == w.kind &&
      HeadingChange(d.back().theta, w.theta) <= kTurnEpsilonRad) {
    d.back() = w;
  } else {
    d.push_back(w);
  }
  junction_ = false;
}

void Simulation::IndexSweeps() {
  sweep_of_.assign(path().size(), -1);
  for (size_t k = 0; k < plan_.plan.sweeps.size(); ++k) {
    const int w = plan_.plan.sweeps[k].waypoint;
    if (w >= 0 && w < static_cast<int>(sweep_of_.size())) sweep_of_[w] = static_cast<int>(k);
  }
}

// Where the robot is, for Replan: a micrometre back along the way it came,
// so that a robot standing on a cell border is in the free cell it came from
// (the replanner takes the cell containing the position as the robot's).
RobotProgress Simulation::Progress() const {
  RobotProgress at;
  at.waypoint = d_seg_ > 0.0 || seg_ == 1 ? seg_ : seg_ - 1;
  at.position = pos_;
  if (d_seg_ > 0.0 || seg_ > 1) {
    const Point2 a = At(path()[at.waypoint - 1]), b = At(path()[at.waypoint]);
    const double len = Dist(a, b);
    constexpr double kBack = 1e-6;
    if (len > 2 * kBack)
      at.position = Point2{pos_.x - kBack * (b.x - a.x) / len, pos_.y - kBack * (b.y - a.y) / len};
  }
  return at;
}

absl::Status Simulation::DoReplan(ReplanMethod method) {
  const Waypoint& a = path()[seg_ - 1];
  const Waypoint& b = path()[seg_];
  const bool mid_segment = d_seg_ > 0.0 && d_seg_ < Dist(At(a), At(b));
  const RobotProgress at = Progress();
  pos_ = *at.position;
  Observations seen;
  seen.cells = std::move(pending_);
  pending_.clear();
  std::vector<uint8_t> flags(found_.size(), 0);
  for (const CellIndex& c : seen.cells) {
    flags[Index(c)] = 1, pending_flag_[Index(c)] = 0, reported_[Index(c)] = 1;
  }
  pending_checked_ = true;

  ReplanOptions ro;
  ro.method = method;
  ro.seed = options_.seed + r_.num_replans;
  ro.tour_time_limit_s = options_.replan_tour_time_limit_s;
  absl::Time t0 = absl::Now();
  absl::StatusOr<ReplanResult> result = source_->Replan(plan_, at, seen, ro);
  bool fell_back = false;
  if (!result.ok() && method != ReplanMethod::kGreedyDetour) {
    std::string cells;
    for (const CellIndex& c : seen.cells) absl::StrAppendFormat(&cells, " (%d,%d)", c.row, c.col);
    r_.problems.push_back(absl::StrFormat(
        "replan %d (%s) failed, greedy detour instead: robot at (%.4f, %.4f) on segment %d of %d, "
        "new cells%s: %s",
        r_.num_replans, ReplanMethodName(method), pos_.x, pos_.y, at.waypoint, path().size() - 1,
        cells, result.status().ToString()));
    ro.method = ReplanMethod::kGreedyDetour;
    result = source_->Replan(plan_, at, seen, ro);
    fell_back = true;
  }
  const double compute_s = absl::ToDoubleSeconds(absl::Now() - t0);
  if (!result.ok()) {
    return absl::InternalError(
        absl::StrFormat("replan %d failed even as greedy detour at (%.4f, %.4f), segment %d: %s",
                        r_.num_replans, pos_.x, pos_.y, at.waypoint, result.status().ToString()));
  }
  const ReplanStats& st = result->stats;
  // Stoppage: the compute time the robot cannot drive through.
  double stoppage = 0.0;
  if (st.method == "unchanged" || (method == ReplanMethod::kGreedyDetour && !fell_back)) {
    stoppage = 0.0;  // a local move: no compute time charged
  } else if (method == ReplanMethod::kFull && !fell_back) {
    stoppage = compute_s;  // the new plan starts at the robot: it waits for all of it
  } else if (st.replanned_encounter >= 0) {
    stoppage = std::max(0.0, compute_s - st.time_to_encounter_s);
  } else {
    stoppage = std::max(0.0, compute_s - TimeToFirstEntry(flags));
  }
  r_.stoppage_s += stoppage;
  ++r_.num_replans;
  r_.num_encounters += st.num_encounters;
  r_.num_greedy_detours += static_cast<int>(st.greedy_detours.size());
  r_.replan_ms.push_back(1000.0 * compute_s);
  r_.replan_points.push_back(pos_);
  r_.replan_methods.push_back(st.method);

  if (mid_segment) {
    Waypoint cut = b;
    cut.x = pos_.x, cut.y = pos_.y;
    drive_s_ += robot_.StraightTime(d_seg_);
    PushDriven(cut);
    junction_ = true;
  }
  // Every replanned path is checked whole, not only the part the robot
  // drives before the next replan.
  if (std::optional<std::string> crossing = CrossesReported(result->plan.path)) {
    r_.problems.push_back(
        absl::StrFormat("the plan from replan %d (%s) %s", r_.num_replans, st.method, *crossing));
  }
  plan_.plan = std::move(result->plan);
  plan_.area = std::move(result->area);
  IndexSweeps();
  seg_ = 1;
  t_seg_ = d_seg_ = 0.0;
  if (!path().empty()) pos_ = At(path()[0]);
  return absl::OkStatus();
}

std::optional<std::string> Simulation::CrossesReported(const std::vector<Waypoint>& path) const {
  bool leaving = true;  // the path may start in the robot's cell, not come back to it
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 a = At(path[i - 1]), b = At(path[i]);
    std::optional<CellIndex> hit;
    TraverseCells(grid_, a, b, [&](CellIndex c) {
      if (leaving && c == here_) return false;
      leaving = false;
      if (!grid_.InBounds(c.row, c.col) || !reported_[Index(c)]) return false;
      hit = c;
      return true;
    });
    if (hit) {
      return absl::StrFormat(
          "crosses cell (%d, %d), reported blocked, on segment %d (%.4f, %.4f) -> (%.4f, %.4f)",
          hit->row, hit->col, i, a.x, a.y, b.x, b.y);
    }
  }
  return std::nullopt;
}

// The path enters a cell the replanner was told is blocked (or one its drive
// grid never had free): a replanner problem. Record it and detour greedily
// around it.
absl::Status Simulation::HandleViolation(CellIndex cell) {
  // Clutter on the end pose: every plan ends there (the replanner joins a
  // blocked end pose from a free neighbour), the robot cannot. Once nothing
  // is left to sweep, the run ends next to it.
  bool sweeps_left = false;
  for (size_t i = seg_; i < path().size(); ++i)
    sweeps_left |= path()[i].kind == SegmentKind::kCoverage;
  if (!sweeps_left && cell == grid_.CellAt(At(path().back()))) {
    end_blocked_ = true;
    return absl::OkStatus();
  }
  r_.problems.push_back(absl::StrFormat(
      "the plan from replan %d (%s) enters cell (%d, %d), %s, from (%.4f, %.4f) on segment %d",
      r_.num_replans, r_.replan_methods.empty() ? "initial" : r_.replan_methods.back(), cell.row,
      cell.col, found_[Index(cell)] ? "reported blocked" : "blocked on the true grid", pos_.x,
      pos_.y, seg_));
  if (++violations_ > 100) {
    r_.completed = false;
    r_.termination = "stopped: more than 100 plans entered blocked cells";
    return absl::OkStatus();
  }
  if (!found_[Index(cell)]) r_.obstacles_found.push_back(cell);
  found_[Index(cell)] = 1;
  pending_.push_back(cell);
  return DoReplan(ReplanMethod::kGreedyDetour);
}

absl::StatusOr<SimulationResult> Simulation::Run() {
  IndexSweeps();
  r_.planned_duration_s = plan_.plan.stats.estimated_duration_s;
  const int planned_cycles = static_cast<int>(plan_.plan.cycles.size());
  const double planned_energy = plan_.plan.stats.energy_total;
  const double time_cap = options_.max_time_factor * r_.planned_duration_s + 3600.0;
  pos_ = At(path()[0]);
  here_ = grid_.CellAt(pos_);
  r_.driven.push_back(path()[0]);
  Sense();
  while (r_.completed) {
    if (!pending_.empty() && !pending_checked_) {
      if (PendingOnPath()) {
        if (r_.num_replans >= options_.max_replans) {
          r_.completed = false;
          r_.termination = absl::StrFormat("stopped: %d replans", r_.num_replans);
          break;
        }
        RETURN_IF_ERROR(DoReplan(method_));
        continue;
      }
      pending_checked_ = true;
    }
    if (seg_ >= static_cast<int>(path().size())) break;
    if (drive_s_ > time_cap) {
      r_.completed = false;
      r_.termination = absl::StrFormat("stopped: %.0f s of driving", drive_s_);
      break;
    }
    const Waypoint& a = path()[seg_ - 1];
    const Waypoint& b = path()[seg_];
    const double length = Dist(At(a), At(b));
    const double total = robot_.StraightTime(length);
    const double t_next = std::min(total, t_seg_ + options_.step_s);
    const double d_next = t_next >= total ? length : DistanceAt(robot_, length, t_next);
    // What the move enters: a cell blocked on the true grid is either a candidate not
    // found yet (touched: the sensor could not see it) or a planning error.
    const Point2 to = length > 0.0 ? Lerp(At(a), At(b), d_next / length) : At(b);
    std::optional<CellIndex> touch, violation, last;
    TraverseCells(grid_, pos_, to, [&](CellIndex c) {
      last = c;
      if (c == here_ || !grid_.InBounds(c.row, c.col) || grid_.IsFree(c)) return false;
      (candidate_[Index(c)] && !found_[Index(c)] ? touch : violation) = c;
      return true;
    });
    if (touch) {
      ++r_.num_touch_detections;
      Observe(*touch);
      continue;
    }
    if (violation) {
      RETURN_IF_ERROR(HandleViolation(*violation));
      if (end_blocked_) break;
      continue;
    }
    if (last) here_ = *last;
    if (b.kind == SegmentKind::kCoverage && sweep_of_[seg_] >= 0) {
      const double t = length > 0.0 ? d_next / length : 1.0;
      for (const CellIndex& c : plan_.plan.sweeps[sweep_of_[seg_]].cells) {
        if (t >= 1.0 || Param(At(a), At(b), grid_.CellCenter(c)) <= t + 1e-9) swept_[Index(c)] = 1;
      }
    }
    t_seg_ = t_next;
    d_seg_ = d_next;
    pos_ = to;
    if (t_next >= total) {
      drive_s_ += total + robot_.TurnTime(HeadingChange(a.theta, b.theta));
      PushDriven(b);
      ++seg_;
      t_seg_ = d_seg_ = 0.0;
      pos_ = At(b);
    }
    Sense();
  }
  if (end_blocked_) {
    r_.termination = absl::StrFormat(
        "completed: the end pose (%.3f, %.3f) lies in a blocked cell; stopped next to it at (%.3f, "
        "%.3f)",
        path().back().x, path().back().y, pos_.x, pos_.y);
  } else if (r_.completed) {
    r_.termination = "completed: the end of the plan was reached";
  }
  const PlanStats s = ComputePathStats(r_.driven, robot_);
  r_.drive_time_s = s.estimated_duration_s;
  r_.total_time_s = r_.drive_time_s + r_.stoppage_s;
  if (options_.plan.battery) {
    r_.battery = DriveBattery(r_.driven, *options_.plan.battery, robot_, options_.recharge_s);
    r_.battery->charge_cycles_planned = planned_cycles;
    r_.battery->energy_planned = planned_energy;
    r_.total_time_s += r_.battery->recharge_time_s;
  }
  r_.num_turns = static_cast<int>(s.num_turns);
  r_.path_length_m = s.coverage_length_m + s.transition_length_m;
  return r_;
}

}  // namespace

absl::Status SimulationOptions::Validate() const {
  if (!(sensor_range_m > 0.0 && sensor_range_m <= 1000.0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("sensor_range_m must be in (0, 1000] m, got %g", sensor_range_m));
  }
  if (!(step_s > 0.0 && step_s <= 60.0)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("step_s must be in (0, 60] s, got %g", step_s));
  }
  if (max_replans < 0) return absl::InvalidArgumentError("max_replans must be >= 0");
  if (!(replan_tour_time_limit_s > 0.0 && replan_tour_time_limit_s <= 3600.0)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "replan_tour_time_limit_s must be in (0, 3600] s, got %g", replan_tour_time_limit_s));
  }
  if (!(max_time_factor > 0.0 && std::isfinite(max_time_factor))) {
    return absl::InvalidArgumentError("max_time_factor must be a positive number");
  }
  if (!(recharge_s >= 0.0 && std::isfinite(recharge_s))) {
    return absl::InvalidArgumentError(
        absl::StrFormat("recharge_s must be a finite value >= 0 s, got %g", recharge_s));
  }
  if (plan.battery) RETURN_IF_ERROR(plan.battery->Validate());
  return plan.robot.Validate();
}

namespace {

absl::Status CheckSameFrame(const OccupancyMap& known, const OccupancyMap& truth) {
  if (known.width() != truth.width() || known.height() != truth.height() ||
      known.resolution() != truth.resolution() || known.origin().x != truth.origin().x ||
      known.origin().y != truth.origin().y) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the known and the true map must have the same size, resolution and origin: known %d x %d "
        "px "
        "at %g m/px from (%g, %g), true %d x %d px at %g m/px from (%g, %g)",
        known.width(), known.height(), known.resolution(), known.origin().x, known.origin().y,
        truth.width(), truth.height(), truth.resolution(), truth.origin().x, truth.origin().y));
  }
  return absl::OkStatus();
}

GridOptions GridOf(const PlanOptions& options) {
  GridOptions go;
  go.cell_size = options.robot.tool_width_m;
  go.min_free_fraction = options.min_free_fraction;
  go.max_cells = EngineLimits().max_grid_cells;
  return go;
}

// Length of `path` inside the interior of the non-free pixels of `map`
// (sampled every quarter pixel; faces and corners may be touched).
double LengthInObstacles(const OccupancyMap& map, const std::vector<Waypoint>& path) {
  const double res = map.resolution();
  auto blocked = [&](double x, double y) {
    const int c = static_cast<int>(std::floor(x)), r = static_cast<int>(std::floor(y));
    return c < 0 || r < 0 || c >= map.width() || r >= map.height() || !map.IsFree(r, c);
  };
  constexpr double kNudge = 1e-6;  // pixels
  double inside = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 a = At(path[i - 1]), b = At(path[i]);
    const double len = Dist(a, b);
    const int n = static_cast<int>(std::ceil(len / (res / 4)));
    for (int k = 0; k < n; ++k) {
      const Point2 p = Lerp(a, b, (k + 0.5) / n);
      const double x = (p.x - map.origin().x) / res, y = (p.y - map.origin().y) / res;
      if (blocked(x - kNudge, y - kNudge) && blocked(x + kNudge, y - kNudge) &&
          blocked(x - kNudge, y + kNudge) && blocked(x + kNudge, y + kNudge)) {
        inside += len / n;
      }
    }
  }
  return inside;
}

}  // namespace

namespace {
// Plans and replans in process.
class LocalPlanSource final : public PlanSource {
 public:
  absl::StatusOr<RetainedPlan> InitialPlan(const OccupancyMap& known,
                                           const PlanOptions& options) override {
    ASSIGN_OR_RETURN(EngineResult planned, PlanCoverageWithArea(known, options));
    RetainedPlan retained;
    retained.plan_id = "simulation";
    retained.map_id = "known";
    retained.plan = std::move(planned.plan);
    retained.request = options.ToRequest();
    retained.area = std::move(planned.area);
    return retained;
  }
  absl::StatusOr<ReplanResult> Replan(const RetainedPlan& plan, const RobotProgress& at,
                                      const Observations& seen,
                                      const ReplanOptions& options) override {
    return covplan::Replan(plan, at, seen, options, &estimator_);
  }

 private:
  ReplanEstimator estimator_;
};
}  // namespace

absl::StatusOr<SimulationResult> Simulate(const OccupancyMap& known, const OccupancyMap& truth,
                                          const SimulationOptions& options, PlanSource* source) {
  RETURN_IF_ERROR(options.Validate());
  RETURN_IF_ERROR(CheckSameFrame(known, truth));
  LocalPlanSource local;
  if (source == nullptr) source = &local;
  ASSIGN_OR_RETURN(RetainedPlan retained, source->InitialPlan(known, options.plan));
  if (retained.plan.grid == nullptr || retained.plan.path.empty()) {
    return absl::InternalError("the initial plan has no grid or no path");
  }
  // Nothing stands where the robot starts or on its dock (the end pose).
  // Battery runs start and end at the station, which the true map itself
  // must leave free (checked below; the CLI keeps its clutter off it).
  std::shared_ptr<OccupancyMap> cleared;
  int64_t cleared_px = 0;
  for (const Waypoint* w : {&retained.plan.path.front(), &retained.plan.path.back()}) {
    if (options.plan.battery) break;
    OccupancyMap probe = cleared != nullptr ? *cleared : truth;
    const int64_t freed = ClearAround(known, {w->x, w->y}, options.plan.robot.tool_width_m, &probe);
    if (freed > 0) cleared = std::make_shared<OccupancyMap>(std::move(probe)), cleared_px += freed;
  }
  const OccupancyMap& true_map = cleared != nullptr ? *cleared : truth;
  const GridOptions go = GridOf(options.plan);
  ASSIGN_OR_RETURN(GridFrame frame, PlanGridFrame(true_map, go));
  const std::vector<double> fractions = CellFreeFractions(true_map, frame);
  ASSIGN_OR_RETURN(Grid true_grid, BuildGridFromFractions(true_map, go, frame, fractions));
  if (options.plan.battery) {
    // The robot must be able to dock: nothing the sensor could find there.
    const Pose2& st = options.plan.battery->station;
    const CellIndex cell = true_grid.CellAt({st.x, st.y});
    if (!true_grid.InBounds(cell.row, cell.col) || !true_grid.IsFree(cell)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "battery.station (%.3f, %.3f) is not in a free cell of the true map", st.x, st.y));
    }
  }
  const Grid& drive = retained.area != nullptr ? *retained.area->drive : *retained.plan.grid;
  if (drive.rows() != true_grid.rows() || drive.cols() != true_grid.cols()) {
    return absl::InternalError("the plan's grid and the true grid differ in shape");
  }
  std::vector<uint8_t> candidate(static_cast<size_t>(drive.size()), 0);
  for (int64_t i = 0; i < drive.size(); ++i) {
    candidate[i] = drive.free_flags()[i] && !true_grid.free_flags()[i];
  }
  Simulation sim(true_map, true_grid, options, std::move(retained), std::move(candidate), source);
  ASSIGN_OR_RETURN(SimulationResult result, sim.Run());
  result.truth_cleared_px = cleared_px;
  result.truth_used = cleared;
  // Coverage against the true map: its free area inside the swept cells.
  const int64_t true_free = true_map.CountFree();
  double swept_free_px = 0.0;
  for (size_t i = 0; i < sim.swept().size(); ++i) {
    if (sim.swept()[i]) swept_free_px += fractions[i] * frame.px_per_cell * frame.px_per_cell;
  }
  result.covered_free_area_ratio = true_free > 0 ? swept_free_px / true_free : 0.0;
  result.length_in_obstacles_m = LengthInObstacles(true_map, result.driven);
  return result;
}

absl::StatusOr<OccupancyMap> CellLevelTruth(const OccupancyMap& known, const OccupancyMap& truth,
                                            const PlanOptions& options) {
  RETURN_IF_ERROR(CheckSameFrame(known, truth));
  const GridOptions go = GridOf(options);
  ASSIGN_OR_RETURN(Grid known_grid, BuildGrid(known, go));
  ASSIGN_OR_RETURN(GridFrame frame, PlanGridFrame(truth, go));
  ASSIGN_OR_RETURN(Grid true_grid,
                   BuildGridFromFractions(truth, go, frame, CellFreeFractions(truth, frame)));
  OccupancyMap out = known;
  for (int r = 0; r < known.height(); ++r) {
    for (int c = 0; c < known.width(); ++c) {
      const int row = static_cast<int>(std::floor((r + 0.5) / frame.px_per_cell));
      const int col = static_cast<int>(std::floor((c + 0.5) / frame.px_per_cell));
      if (known_grid.IsFree(row, col) && !true_grid.IsFree(row, col))
        out.set(r, c, CellState::kOccupied);
    }
  }
  return out;
}

absl::StatusOr<OfflineBound> OfflineLowerBound(const OccupancyMap& truth,
                                               const PlanOptions& options) {
  ASSIGN_OR_RETURN(CoveragePlan plan, PlanCoverage(truth, options));
  OfflineBound b;
  b.duration_s = plan.stats.estimated_duration_s;
  b.covered_free_area_ratio = plan.stats.covered_free_area_ratio;
  b.num_ranks = plan.stats.num_ranks;
  b.charge_cycles = static_cast<int>(plan.cycles.size());
  return b;
}

}  // namespace covplan
