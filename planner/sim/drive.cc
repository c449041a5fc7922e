#include "planner/sim/drive.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "planner/common/status_macros.h"
#include "planner/sim/battery_run.h"
#include "planner/tour/path_timing.h"

namespace covplan::sim_internal {
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

}  // namespace

void SimulatedDrive::Observe(CellIndex c) {
  const int64_t i = Index(c);
  if (found_[i]) return;
  found_[i] = pending_flag_[i] = 1;
  pending_.push_back(c);
  pending_checked_ = false;
  r_.obstacles_found.push_back(c);
}

void SimulatedDrive::Sense() {
  for (const CellIndex& c : sensor_.Scan(pos_, candidate_, found_)) Observe(c);
  SenseCrossings();
}

template <typename F>
bool SimulatedDrive::ScanRemaining(F f) const {
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
bool SimulatedDrive::PendingOnPath() const {
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
double SimulatedDrive::TimeToFirstEntry(const std::vector<uint8_t>& flags) const {
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

void SimulatedDrive::PushDriven(const Waypoint& w) {
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

void SimulatedDrive::IndexSweeps() {
  sweep_of_.assign(path().size(), -1);
  for (size_t k = 0; k < plan_.plan.sweeps.size(); ++k) {
    const int w = plan_.plan.sweeps[k].waypoint;
    if (w >= 0 && w < static_cast<int>(sweep_of_.size())) sweep_of_[w] = static_cast<int>(k);
  }
}

// Where the robot is, for Replan: a micrometre back along the way it came,
// so that a robot standing on a cell border is in the free cell it came from
// (the replanner takes the cell containing the position as the robot's).
RobotProgress SimulatedDrive::Progress() const {
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

void SimulatedDrive::SweepTo(double d) {
  const Waypoint& a = path()[seg_ - 1];
  const Waypoint& b = path()[seg_];
  if (b.kind != SegmentKind::kCoverage || sweep_of_[seg_] < 0) return;
  const double length = Dist(At(a), At(b));
  const double t = length > 0.0 ? d / length : 1.0;
  for (const CellIndex& c : plan_.plan.sweeps[sweep_of_[seg_]].cells) {
    if (t >= 1.0 || Param(At(a), At(b), grid_.CellCenter(c)) <= t + 1e-9) swept_[Index(c)] = 1;
  }
}

absl::Status SimulatedDrive::DoReplan(ReplanMethod method) {
  const Waypoint& a = path()[seg_ - 1];
  const Waypoint& b = path()[seg_];
  // The replan takes what the tool covers where the robot stands as swept
  // (on a coverage segment's first cell, before any step: its start).
  SweepTo(d_seg_);
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
  wait_s_ += stoppage;  // waited out by Step, up to the clock bound it is given
  ++r_.num_replans;
  r_.num_encounters += st.num_encounters;
  r_.num_greedy_detours += static_cast<int>(st.greedy_detours.size());
  r_.replan_ms.push_back(1000.0 * compute_s);
  r_.replan_points.push_back(pos_);
  r_.replan_methods.push_back(st.method);
  walled_in_ = st.robot_cell_kept_free;

  if (mid_segment) {
    Waypoint cut = b;
    cut.x = pos_.x, cut.y = pos_.y;
    drive_s_ += robot_.StraightTime(d_seg_);
    clock_s_ = StopClock();
    PushDriven(cut);
    junction_ = true;
  }
  // Every replanned path is checked whole, not only the part the robot
  // drives before the next replan.
  // (A walled-in robot's plan crosses the reported cell kept as its way out,
  // free on its drive grid, and says so: the drive ends there, below. Any
  // other reported cell it crosses is a problem; a server's answer has no
  // drive grid, so there nothing is checked.)
  const bool has_drive = result->area != nullptr && result->area->drive != nullptr;
  std::optional<std::string> crossing;
  if (!st.robot_cell_kept_free || has_drive) {
    crossing = CrossesReported(result->plan.path,
                               st.robot_cell_kept_free ? result->area->drive.get() : nullptr);
  }
  if (crossing) {
    r_.problems.push_back(
        absl::StrFormat("the plan from replan %d (%s) %s", r_.num_replans, st.method, *crossing));
  }
  plan_.plan = std::move(result->plan);
  plan_.area = std::move(result->area);
  IndexSweeps();
  seg_ = 1;
  t_seg_ = d_seg_ = 0.0;
  if (!path().empty()) pos_ = At(path()[0]);
  FindCrossings();
  SenseCrossings();
  return absl::OkStatus();
}

std::optional<std::string> SimulatedDrive::CrossesReported(const std::vector<Waypoint>& path,
                                                           const Grid* kept) const {
  bool leaving = true;  // the path may start in the robot's cell, not come back to it
  for (size_t i = 1; i < path.size(); ++i) {
    const Point2 a = At(path[i - 1]), b = At(path[i]);
    std::optional<CellIndex> hit;
    TraverseCells(grid_, a, b, [&](CellIndex c) {
      if (leaving && c == here_) return false;
      leaving = false;
      if (!grid_.InBounds(c.row, c.col) || !reported_[Index(c)]) return false;
      if (kept != nullptr && kept->IsFree(c)) return false;  // the walled-in robot's way out
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
absl::Status SimulatedDrive::HandleViolation(CellIndex cell) {
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
  // Walled in: the replanner kept the robot's only way out free although it
  // was reported blocked (it is, on the true grid). No plan can get the
  // robot out; replanning again would only repeat that answer.
  const bool kept_cell = plan_.area == nullptr || plan_.area->drive == nullptr ||
                         plan_.area->drive->IsFree(cell);  // a server's answer: no grid
  if (walled_in_ && found_[Index(cell)] && kept_cell) {
    r_.completed = false;
    r_.termination = absl::StrFormat(
        "stopped: walled in at (%.4f, %.4f): replan %d found no clean move out of the robot's "
        "cell (its neighbours blocked, cut off by earlier obstacles, or reached only by clipping "
        "one) and kept cell (%d, %d), reported blocked, as the way out (robot_cell_kept_free)",
        pos_.x, pos_.y, r_.num_replans, cell.row, cell.col);
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

void SimulatedDrive::Start() {
  started_ = true;
  IndexSweeps();
  r_.planned_duration_s = plan_.plan.stats.estimated_duration_s;
  planned_cycles_ = static_cast<int>(plan_.plan.cycles.size());
  planned_energy_ = plan_.plan.stats.energy_total;
  time_cap_ = options_.max_time_factor * r_.planned_duration_s + 3600.0;
  pos_ = At(path()[0]);
  here_ = grid_.CellAt(pos_);
  r_.driven.push_back(path()[0]);
  FindCrossings();
  Sense();
}

double SimulatedDrive::StopClock() const {
  const Waypoint& a = path()[seg_ - 1];
  const Waypoint& b = path()[seg_];
  return clock_s_ + robot_.StraightTime(d_seg_) + robot_.TurnTime(HeadingChange(a.theta, b.theta));
}

double SimulatedDrive::clock_s() const {
  double t = clock_s_;
  if (started_ && !finished_ && seg_ < static_cast<int>(path().size()) && t_seg_ > 0.0) {
    t += robot_.TurnTime(HeadingChange(path()[seg_ - 1].theta, path()[seg_].theta)) + t_seg_;
  }
  return t;
}

Pose2 SimulatedDrive::pose() const {
  if (!started_) return {path()[0].x, path()[0].y, path()[0].theta};
  const int n = static_cast<int>(path().size());
  const double theta = seg_ >= n      ? path().back().theta
                       : t_seg_ > 0.0 ? path()[seg_].theta
                                      : path()[seg_ - 1].theta;
  return {pos_.x, pos_.y, theta};
}

absl::StatusOr<bool> SimulatedDrive::Step(double until_s) {
  if (wait_s_ > 0.0) {  // waiting for a replan: the clock runs, the robot stands
    const double waited = std::min(wait_s_, std::max(0.0, until_s - clock_s()));
    clock_s_ += waited;
    r_.stoppage_s += waited;
    wait_s_ -= waited;
    if (wait_s_ > 1e-12) return false;
    wait_s_ = 0.0;
  }
  if (!pending_.empty() && !pending_checked_) {
    if (PendingOnPath()) {
      if (r_.num_replans >= options_.max_replans) {
        r_.completed = false;
        r_.termination = absl::StrFormat("stopped: %d replans", r_.num_replans);
        return finished_ = true, false;
      }
      // A replan mid-segment stops the robot there, which takes longer than
      // driving on (it brakes): that stop must not carry the clock past
      // until_s (a fleet robot fails or takes a new plan then). It replans
      // at the next call.
      if (t_seg_ > 0.0 && StopClock() > until_s + 1e-9) return false;
      RETURN_IF_ERROR(DoReplan(method_));
      return true;
    }
    pending_checked_ = true;
  }
  if (seg_ >= static_cast<int>(path().size())) return finished_ = true, false;
  if (drive_s_ > time_cap_) {
    r_.completed = false;
    r_.termination = absl::StrFormat("stopped: %.0f s of driving", drive_s_);
    return finished_ = true, false;
  }
  const Waypoint& a = path()[seg_ - 1];
  const Waypoint& b = path()[seg_];
  const double length = Dist(At(a), At(b));
  const double total = robot_.StraightTime(length);
  const double turn = robot_.TurnTime(HeadingChange(a.theta, b.theta));
  // The straight time this segment may reach before the clock passes until_s.
  const double straight_left = until_s - clock_s_ - turn;
  if (straight_left <= t_seg_ + 1e-9) return false;
  const double t_next = std::min({total, t_seg_ + options_.step_s, straight_left});
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
  if (!touch && !violation) touch = TouchCrossing(d_next);
  if (touch) {
    ++r_.num_touch_detections;
    Observe(*touch);
    return true;
  }
  if (violation) {
    RETURN_IF_ERROR(HandleViolation(*violation));
    if (end_blocked_ || !r_.completed) return finished_ = true, false;
    return true;
  }
  if (last) here_ = *last;
  SweepTo(d_next);
  t_seg_ = t_next;
  d_seg_ = d_next;
  pos_ = to;
  if (t_next >= total) {
    drive_s_ += total + turn;
    clock_s_ += total + turn;
    PushDriven(b);
    ++seg_;
    t_seg_ = d_seg_ = 0.0;
    pos_ = At(b);
  }
  if (source_->WatchesMoves()) source_->Moved(Progress(), clock_s());
  Sense();
  return true;
}

absl::Status SimulatedDrive::RunUntil(double until_s) {
  if (!started_) Start();
  while (!finished_ && clock_s() < until_s - 1e-9) {
    ASSIGN_OR_RETURN(const bool more, Step(until_s));
    if (!more) break;
  }
  return absl::OkStatus();
}

absl::StatusOr<SimulationResult> SimulatedDrive::Run() {
  RETURN_IF_ERROR(RunUntil(std::numeric_limits<double>::infinity()));
  return Finish();
}

SimulationResult SimulatedDrive::Finish() {
  if (!started_) Start();
  if (!finished_ && d_seg_ > 0.0) {  // stopped mid-segment: the path ends here
    Waypoint cut = path()[seg_];
    cut.x = pos_.x, cut.y = pos_.y;
    PushDriven(cut);
  }
  if (end_blocked_) {
    r_.termination = absl::StrFormat(
        "completed: the end pose (%.3f, %.3f) lies in a blocked cell; stopped next to it at (%.3f, "
        "%.3f)",
        path().back().x, path().back().y, pos_.x, pos_.y);
  } else if (!finished_) {
    r_.termination = absl::StrFormat("stopped at %.3f s before the end of the plan", clock_s());
  } else if (r_.completed && walled_in_) {
    // Walled in with its own cell kept: the last plan stayed in it.
    r_.completed = false;
    r_.termination = absl::StrFormat(
        "stopped: walled in at (%.4f, %.4f): replan %d found no clean move out of the robot's "
        "cell and kept it free (robot_cell_kept_free)",
        pos_.x, pos_.y, r_.num_replans);
  } else if (r_.completed) {
    r_.termination = "completed: the end of the plan was reached";
  }
  const PlanStats s = ComputePathStats(r_.driven, robot_);
  r_.drive_time_s = s.estimated_duration_s;
  r_.total_time_s = r_.drive_time_s + r_.stoppage_s;
  if (options_.plan.battery) {
    r_.battery = DriveBattery(r_.driven, *options_.plan.battery, robot_, options_.recharge_s);
    r_.battery->charge_cycles_planned = planned_cycles_;
    r_.battery->energy_planned = planned_energy_;
    r_.total_time_s += r_.battery->recharge_time_s;
  }
  r_.num_turns = static_cast<int>(s.num_turns);
  r_.path_length_m = s.coverage_length_m + s.transition_length_m;
  r_.swept = swept_;
  return r_;
}

}  // namespace covplan::sim_internal
