#include "planner/fleet/bounds.h"

#include <optional>

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "planner/fleet/assignment.h"
#include "planner/fleet/detour_turn.h"
#include "planner/fleet/geodesic.h"
#include "planner/fleet/one_tree.h"

namespace covplan {
namespace {

// Seconds robot `robot` needs to drive unit `u` as the tour does, from its
// entry point already heading along its first segment.
double UnitTime(const TourUnits& units, const TourUnit& u, const RobotModel& robot) {
  double t = 0.0;
  for (int i = u.entry_waypoint + 1; i <= u.exit_waypoint; ++i) {
    const Waypoint& a = units.path[i - 1];
    const Waypoint& b = units.path[i];
    t += robot.StraightTime(std::hypot(b.x - a.x, b.y - a.y));
    if (i > u.entry_waypoint + 1) t += robot.TurnTime(HeadingChange(a.theta, b.theta));
  }
  return t;
}

double Reversed(double heading) { return heading + M_PI; }

// The least total turning (radians, up to a full turn) of any path of
// straight segments and turns in place from `a` heading `ha` to `b` heading
// `hb` (docs/fleet.md): the headings the path takes span an arc. Under half
// a turn that arc holds the displacement's direction d (it is a positive sum
// of the segments' headings) and the turning walks from ha through d to hb;
// otherwise the walk covers an arc of half a turn or more from ha to hb,
// which takes at least a full turn less the net change. Never less than the
// net change.
double TurnBound(double ha, double hb, Point2 a, Point2 b) {
  const double net = HeadingChange(ha, hb);
  if (std::hypot(b.x - a.x, b.y - a.y) <= 1e-9) return net;
  const double d = std::atan2(b.y - a.y, b.x - a.x);
  return std::max(net, std::min(2.0 * M_PI - net, HeadingChange(ha, d) + HeadingChange(d, hb)));
}

// Seconds to turn in place by `angle` radians in all (up to a full turn;
// RobotModel::TurnTime takes a heading change, at most half a turn).
double TurningTime(const RobotModel& robot, double angle) {
  const double half = std::min(angle, M_PI);
  return robot.TurnTime(half) + robot.TurnTime(std::max(0.0, angle - half));
}

}  // namespace

namespace {

// Variant 0 of a unit: forwards (entered at its entry along entry_heading,
// left at its exit); variant 1: backwards. Points (for the geodesic bound):
// 2u is unit u's entry, 2u + 1 its exit, 2n + r robot r's start, 2n + k + r
// its end.
struct End {
  Point2 in, out;
  double h_in, h_out;
  int in_pt, out_pt;
};

// Sizes up to which the matching (points) and the assignment (units and
// robots) bounds are computed: both are O(n^3) assignments over the moves
// between points, priced once.
constexpr int kMaxMatching = 600;
constexpr int kMaxAssignment = 400;
// Points up to which the Held-Karp bound runs, and the vertex pairs its
// subgradient steps may visit (about 0.1 s).
constexpr int kMaxOneTree = 1200;
constexpr int64_t kOneTreeWork = 100'000'000;
// Moves up to this many cells long are checked for a detour's turning.
constexpr double kDetourReach = 12.0;
// Square visits all geodesic searches of one bound may take (about 0.1 s):
// above it the searches stop at a depth (their bounds stay valid).
constexpr int64_t kSearchBudget = 10'000'000;

class BoundInput {
 public:
  BoundInput(const TourUnits& units, const std::vector<FleetRobot>& robots, const Grid* drive)
      : robots_(robots) {
    n_ = static_cast<int>(units.units.size());
    k_ = static_cast<int>(robots.size());
    fastest_ = robots[0].robot;
    for (const FleetRobot& r : robots) {
      fastest_.max_speed_mps = std::max(fastest_.max_speed_mps, r.robot.max_speed_mps);
      fastest_.turn_rate_deg_s = std::max(fastest_.turn_rate_deg_s, r.robot.turn_rate_deg_s);
      fastest_.acceleration_mps2 = std::max(fastest_.acceleration_mps2, r.robot.acceleration_mps2);
    }
    ends_.resize(2 * n_);
    time_.assign(k_, std::vector<double>(n_));
    points_.resize(2 * n_ + 2 * k_);
    for (int u = 0; u < n_; ++u) {
      const TourUnit& t = units.units[u];
      ends_[2 * u] = {t.entry, t.exit, t.entry_heading, t.exit_heading, 2 * u, 2 * u + 1};
      ends_[2 * u + 1] = {t.exit,    t.entry, Reversed(t.exit_heading), Reversed(t.entry_heading),
                          2 * u + 1, 2 * u};
      points_[2 * u] = t.entry;
      points_[2 * u + 1] = t.exit;
      for (int r = 0; r < k_; ++r) time_[r][u] = UnitTime(units, t, robots[r].robot);
    }
    for (int r = 0; r < k_; ++r) {
      const std::optional<Pose2>& s = robot(r).start;
      const std::optional<Pose2>& e = robot(r).end;
      if (s) points_[start_pt(r)] = {s->x, s->y};
      if (e) points_[end_pt(r)] = {e->x, e->y};
    }
    if (drive != nullptr) SearchRows(*drive);
    drive_ = drive;
  }
  int n() const { return n_; }
  int k() const { return k_; }
  int start_pt(int r) const { return 2 * n_ + r; }
  int end_pt(int r) const { return 2 * n_ + k_ + r; }
  const End& end(int variant) const { return ends_[variant]; }
  double time(int r, int u) const { return time_[r][u]; }
  double fastest_time(int u) const {
    double best = INFINITY;
    for (int r = 0; r < k_; ++r) best = std::min(best, time_[r][u]);
    return best;
  }
  const RobotModel& robot(int r) const { return robots_[r].robot; }
  double StraightTime(double length) const { return fastest_.StraightTime(length); }
  // The least length of any drive path between points a and b: the straight
  // line, or (D - 1) h over the squares of GeodesicHops when longer.
  double Length(int a, int b) const {
    const Point2 p = points_[a], q = points_[b];
    const double line = std::hypot(q.x - p.x, q.y - p.y);
    if (!geo_) return line;
    int hops = 0;
    if (row_[a] >= 0) {
      hops = hops_[static_cast<size_t>(row_[a]) * points_.size() + b];
    } else if (row_[b] >= 0) {
      hops = hops_[static_cast<size_t>(row_[b]) * points_.size() + a];
    } else if (geo_->source() == a) {
      hops = geo_->Hops(b);
    } else if (geo_->source() == b) {
      hops = geo_->Hops(a);
    }
    return std::max(line, geo_->MinLength(hops));
  }
  // Points without a row are searched one at a time (CheapestEntries): the
  // hops from `point` to every other point, until the next Focus.
  void Focus(int point) {
    if (geo_ && row_[point] < 0 && geo_->source() != point) geo_->Search(point, max_hops_);
  }
  // The least time of any move from point a heading ha to point b heading
  // hb: straight moves from rest to rest take at least one move of their
  // summed length (StraightTime is concave), plus the least turning
  // (TurnBound, or the detour's when larger). QuickMove leaves the detour
  // out: it is never more than Move, so a search can skip the detour of a
  // move whose quick cost cannot beat the best found.
  double Move(int a, double ha, int b, double hb) const {
    double turn = TurnBound(ha, hb, points_[a], points_[b]);
    if (drive_ != nullptr && turn < 2.0 * M_PI) {
      turn = std::max(turn, DetourTurnBound(*drive_, points_[a], ha, points_[b], hb,
                                            kDetourReach * drive_->cell_size()));
    }
    return fastest_.StraightTime(Length(a, b)) + TurningTime(fastest_, turn);
  }
  double QuickMove(int a, double ha, int b, double hb) const {
    return fastest_.StraightTime(Length(a, b)) +
           TurningTime(fastest_, TurnBound(ha, hb, points_[a], points_[b]));
  }
  // The cheapest move into unit u (either direction) from robot r's start
  // (0 when it has none).
  double FromStart(int r, int u) const {
    return std::min(FromStartVariant(r, 2 * u), FromStartVariant(r, 2 * u + 1));
  }
  // Into variant v (= 2u + direction) from robot r's start; out of variant v
  // to robot r's end (0 without a start or end).
  double FromStartVariant(int r, int v) const {
    const std::optional<Pose2>& s = robot(r).start;
    return s ? Move(start_pt(r), s->theta, ends_[v].in_pt, ends_[v].h_in) : 0.0;
  }
  double ToEndVariant(int r, int v) const {
    return robot(r).end ? fastest_.StraightTime(Length(ends_[v].out_pt, end_pt(r))) : 0.0;
  }

 private:
  // The hops from every point when the assignment (and the matching) will
  // want every pair (at most 800 x 800 hop counts), else from the robots'
  // starts and ends only; the searches stop at a depth that keeps them all
  // within kSearchBudget.
  void SearchRows(const Grid& drive) {
    const int num = static_cast<int>(points_.size());
    geo_.emplace(drive, points_);
    const bool dense = n_ + k_ <= kMaxAssignment;
    // Dense: one search per point; sparse: one per robot pose here and one
    // per unit entry in CheapestEntries.
    const double area = static_cast<double>(kSearchBudget) / std::max(1, num);
    if (area < static_cast<double>(geo_->open_squares()))
      max_hops_ = std::max(1, static_cast<int>((std::sqrt(area) - 1.0) / 2.0));
    row_.assign(num, -1);
    std::vector<int> sources;
    for (int p = dense ? 0 : 2 * n_; p < num; ++p) {
      const bool robot_point = p >= 2 * n_;
      const int r = robot_point ? (p - 2 * n_) % k_ : 0;
      if (robot_point && !(p < 2 * n_ + k_ ? robot(r).start : robot(r).end)) continue;
      row_[p] = static_cast<int>(sources.size());
      sources.push_back(p);
    }
    hops_.assign(sources.size() * static_cast<size_t>(num), 0);
    for (size_t i = 0; i < sources.size(); ++i) {
      geo_->Search(sources[i], max_hops_);
      for (int q = 0; q < num; ++q) hops_[i * num + q] = geo_->Hops(q);
    }
  }

  const std::vector<FleetRobot>& robots_;
  const Grid* drive_ = nullptr;
  int n_ = 0, k_ = 0;
  RobotModel fastest_;
  std::vector<End> ends_;
  std::vector<std::vector<double>> time_;
  std::vector<Point2> points_;
  std::optional<GeodesicHops> geo_;
  int max_hops_ = -1;
  std::vector<int> row_;       // per point: its row of hops_, or -1
  std::vector<int32_t> hops_;  // [row][point]
};

// Sum of the cheapest way into each unit from another unit's exit or a start,
// with the k largest savings of a start taken off. Exits are bucketed on a
// square grid and searched ring by ring until no nearer bucket can beat the
// best move found.
double CheapestEntries(BoundInput& in) {
  const int n = in.n(), k = in.k();
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (int w = 0; w < 2 * n; ++w) {
    const Point2 p = in.end(w).out;
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
  const double span = std::max({x1 - x0, y1 - y0, 1e-6});
  const int side = std::max(1, static_cast<int>(std::sqrt(2.0 * n)));
  const double bucket = span / side + 1e-9;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(side) * side);
  auto bx = [&](double x) { return std::clamp(static_cast<int>((x - x0) / bucket), 0, side - 1); };
  auto by = [&](double y) { return std::clamp(static_cast<int>((y - y0) / bucket), 0, side - 1); };
  for (int w = 0; w < 2 * n; ++w)
    buckets[by(in.end(w).out.y) * side + bx(in.end(w).out.x)].push_back(w);
  auto cheapest_in = [&](int u, const End& e) {
    double best = INFINITY;
    const int cx = bx(e.in.x), cy = by(e.in.y);
    in.Focus(e.in_pt);
    for (int ring = 0; ring <= side; ++ring) {
      // Every exit in this ring or beyond is at least this far away (and
      // Length is at least the straight line).
      if (in.StraightTime(std::max(0, ring - 1) * bucket) >= best) break;
      for (int gy = cy - ring; gy <= cy + ring; ++gy) {
        for (int gx = cx - ring; gx <= cx + ring; ++gx) {
          if (std::max(std::abs(gx - cx), std::abs(gy - cy)) != ring) continue;
          if (gx < 0 || gy < 0 || gx >= side || gy >= side) continue;
          for (int w : buckets[gy * side + gx]) {
            if (w / 2 == u) continue;
            const End& x = in.end(w);
            if (in.QuickMove(x.out_pt, x.h_out, e.in_pt, e.h_in) < best)
              best = std::min(best, in.Move(x.out_pt, x.h_out, e.in_pt, e.h_in));
          }
        }
      }
    }
    return best;
  };
  double sum = 0.0;
  std::vector<double> saving;
  for (int u = 0; u < n; ++u) {
    double from_unit = std::min(cheapest_in(u, in.end(2 * u)), cheapest_in(u, in.end(2 * u + 1)));
    double from_start = INFINITY;
    for (int r = 0; r < k; ++r) from_start = std::min(from_start, in.FromStart(r, u));
    if (!std::isfinite(from_unit)) from_unit = from_start;  // a single unit
    sum += from_unit;
    saving.push_back(std::max(0.0, from_unit - from_start));
  }
  std::sort(saving.begin(), saving.end(), std::greater<>());
  for (int i = 0; i < std::min(k, n); ++i) sum -= saving[i];
  return sum;
}

// The moves between the 2n + 2k points (point 2u + v is unit u's end where
// variant v enters it and variant 1 - v leaves it; then the starts, then the
// ends): symmetric, +inf where no move of a fleet plan goes (a unit's own
// two ends; a start with a start, an end or another robot's end). A start
// with its own robot's end costs 0 (a robot given nothing).
std::vector<double> MoveMatrix(const BoundInput& in) {
  const int n = in.n(), k = in.k(), size = 2 * n + 2 * k;
  std::vector<double> c(static_cast<size_t>(size) * size, INFINITY);
  auto set = [&](int a, int b, double v) {
    c[static_cast<size_t>(a) * size + b] = v;
    c[static_cast<size_t>(b) * size + a] = v;
  };
  // Leaving point a heads along the exit heading of the variant that ends
  // there (a ^ 1). The move back from b to a costs the same: its headings
  // and direction are those of a -> b reversed.
  for (int a = 0; a < 2 * n; ++a) {
    const End& leave = in.end(a ^ 1);
    for (int b = a + 1; b < 2 * n; ++b) {
      if (a / 2 == b / 2) continue;
      const End& enter = in.end(b);
      set(a, b, in.Move(leave.out_pt, leave.h_out, enter.in_pt, enter.h_in));
    }
  }
  for (int r = 0; r < k; ++r) {
    const int start = 2 * n + r, end = 2 * n + k + r;
    for (int a = 0; a < 2 * n; ++a) {
      set(start, a, in.FromStartVariant(r, a));
      set(end, a, in.ToEndVariant(r, a ^ 1));
    }
    set(start, end, 0.0);
  }
  return c;
}

// The least total cost of the moves of any k paths start_r -> units ->
// end_r: the moves pair up the units' two ends, the starts and the ends, so
// they form a perfect matching of those 2n + 2k points. A lower bound of
// the minimum-cost perfect matching (half the assignment over the points,
// PerfectMatchingLowerBound) keeps, unlike the assignment over the units,
// each unit driven in one direction.
std::optional<double> MatchedMoves(const std::vector<double>& m, int n, int k) {
  return PerfectMatchingLowerBound(m, 2 * (n + k));
}

// The least total cost of the moves of any k paths, start_r -> units ->
// end_r, that enter every unit once: the assignment relaxation over the
// predecessors (unit exits, starts) and successors (unit entries, ends),
// each arc the cheapest of its directions in the point matrix `m`.
std::optional<double> AssignedMoves(const std::vector<double>& m, int n, int k) {
  const int points = 2 * n + 2 * k, size = n + k;
  auto move = [&](int a, int b) { return m[static_cast<size_t>(a) * points + b]; };
  // The cheapest move leaving one of the points a0, a0 + 1 (or a0 alone)
  // into one of b0, b0 + 1 (or b0 alone).
  auto cheapest = [&](int a0, int a_count, int b0, int b_count) {
    double best = INFINITY;
    for (int a = a0; a < a0 + a_count; ++a) {
      for (int b = b0; b < b0 + b_count; ++b) best = std::min(best, move(a, b));
    }
    return best;
  };
  std::vector<double> c(static_cast<size_t>(size) * size, INFINITY);
  auto at = [&](int row, int col) -> double& { return c[static_cast<size_t>(row) * size + col]; };
  for (int w = 0; w < n; ++w) {
    for (int u = 0; u < n; ++u) {
      if (u != w) at(w, u) = cheapest(2 * w, 2, 2 * u, 2);
    }
    for (int r = 0; r < k; ++r) at(w, n + r) = cheapest(2 * w, 2, 2 * n + k + r, 1);
  }
  for (int r = 0; r < k; ++r) {
    for (int u = 0; u < n; ++u) at(n + r, u) = cheapest(2 * n + r, 1, 2 * u, 2);
    at(n + r, n + r) = 0.0;  // a robot given nothing
  }
  return MinAssignmentCost(c, size);
}

// The same moves with the subtours the matching allows eliminated: join
// each unit's two ends (the unit, its time counted apart) and robot r's end
// to robot r + 1's start (a free link), and the k paths chained in turn are
// one cycle through all the points holding those forced edges. Its least
// cost is at least the Held-Karp bound (one_tree.h).
std::optional<double> OneTreeMoves(std::vector<double> c, int n, int k) {
  const int size = 2 * n + 2 * k;
  std::vector<int> partner(size);
  auto force = [&](int a, int b) {
    partner[a] = b, partner[b] = a;
    c[static_cast<size_t>(a) * size + b] = c[static_cast<size_t>(b) * size + a] = 0.0;
  };
  for (int u = 0; u < n; ++u) force(2 * u, 2 * u + 1);
  for (int r = 0; r < k; ++r) force(2 * n + k + r, 2 * n + (r + 1) % k);
  return HeldKarpBound(c, partner, kOneTreeWork);
}

}  // namespace

MakespanBound MakespanLowerBound(const TourUnits& units, const std::vector<FleetRobot>& robots,
                                 const Grid* drive) {
  MakespanBound bound;
  if (units.units.empty() || robots.empty()) return bound;
  BoundInput in(units, robots, drive);
  const int n = in.n(), k = in.k();
  double work = 0.0;
  for (int u = 0; u < n; ++u) work += in.fastest_time(u);
  std::optional<double> moves;
  auto keep = [&](const std::optional<double>& v) {
    if (v && (!moves || *v > *moves)) moves = v;
  };
  if (2 * (n + k) <= kMaxOneTree) {  // every size cap below is within it
    std::vector<double> matrix = MoveMatrix(in);
    if (2 * (n + k) <= kMaxMatching) keep(MatchedMoves(matrix, n, k));
    if (n + k <= kMaxAssignment) keep(AssignedMoves(matrix, n, k));
    keep(OneTreeMoves(std::move(matrix), n, k));
  }
  work += moves.has_value() ? *moves : CheapestEntries(in);
  bound.work_s = std::max(0.0, work) / k;
  // Some robot must drive each unit, from its start and back to its end.
  for (int u = 0; u < n; ++u) {
    double best = INFINITY;
    for (int r = 0; r < k; ++r) {
      const RobotModel& m = in.robot(r);
      for (int v = 0; v < 2; ++v) {
        const End& e = in.end(2 * u + v);
        double t = in.time(r, u);
        if (m.start) t += m.StraightTime(in.Length(in.start_pt(r), e.in_pt));
        if (m.end) t += m.StraightTime(in.Length(e.out_pt, in.end_pt(r)));
        best = std::min(best, t);
      }
    }
    bound.reach_s = std::max(bound.reach_s, best);
  }
  return bound;
}

}  // namespace covplan
