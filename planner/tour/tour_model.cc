#include "planner/tour/tour_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"
#include "planner/tour/path_timing.h"

namespace covplan {
namespace {

Termination OrderTermination(bool stopped_early, const StopToken& stop, const char* solver) {
  if (!stopped_early) return Termination::Converged(absl::StrFormat("%s search converged", solver));
  if (stop.cancelled()) {
    return Termination::LimitReached(
        TerminationLimit::kCancelled,
        absl::StrFormat("%s search cancelled; best tour kept", solver));
  }
  if (stop.ShouldStop()) {
    return Termination::LimitReached(TerminationLimit::kDeadline,
                                     absl::StrFormat("%s search stopped by the deadline", solver));
  }
  return Termination::LimitReached(TerminationLimit::kTime,
                                   absl::StrFormat("%s search used its whole time limit", solver));
}

}  // namespace

double TravelTimeCost::Polyline(const std::vector<Point2>& points, std::optional<double> heading_in,
                                std::optional<double> heading_out) const {
  return TimePolyline(robot_, points, heading_in, heading_out).time_s;
}

void TourModel::IndexVertices() {
  const int m = num_elements();
  first_.assign(m + 1, 0);
  for (int e = 0; e < m; ++e) first_[e + 1] = first_[e] + num_variants(e);
  element_of_.resize(first_[m]);
  for (int e = 0; e < m; ++e) {
    std::fill(element_of_.begin() + first_[e], element_of_.begin() + first_[e + 1], e);
  }
}

int TourModel::num_vertices() const { return first_.empty() ? 0 : first_.back(); }
int TourModel::first_vertex(int element) const { return first_[element]; }
int TourModel::element_of(int vertex) const { return element_of_[vertex]; }

double TourModel::TourCost(const std::vector<int>& vertices) const {
  if (vertices.empty()) return 0.0;
  double t = FromStart(vertices[0]);
  for (size_t i = 1; i < vertices.size(); ++i) t += Between(vertices[i - 1], vertices[i]);
  return t + ToEnd(vertices.back());
}

absl::StatusOr<TourOrder> GreedyOrderer::Order(const TourModel& model,
                                               const StopToken& stop) const {
  const int n = model.num_vertices();
  std::vector<bool> used(model.num_elements(), false);
  TourOrder tour;
  int current = -1;
  for (int step = 0; step < model.num_elements(); ++step) {
    if ((step & 63) == 63 && stop.cancelled())
      return absl::CancelledError("greedy ordering cancelled");
    int best = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    for (int v = 0; v < n; ++v) {
      if (used[model.element_of(v)]) continue;
      const double c = current < 0 ? model.FromStart(v) : model.Between(current, v);
      if (c < best_cost) best_cost = c, best = v;
    }
    if (best < 0) return absl::InternalError("greedy ordering found no reachable element");
    used[model.element_of(best)] = true;
    tour.vertices.push_back(best);
    current = best;
  }
  tour.cost = model.TourCost(tour.vertices);
  tour.termination = Termination::Converged("greedy order (no search)");
  return tour;
}

bool BuildGtspInstance(const TourModel& model, const StopToken& stop, GtspInstance* inst) {
  const int n = model.num_vertices();
  const int start = n, end = model.has_end() ? n + 1 : -1;
  inst->num_vertices = n + 1 + (model.has_end() ? 1 : 0);
  const double inf = GtspInstance::kInfeasibleCost;
  inst->costs.assign(static_cast<size_t>(inst->num_vertices) * inst->num_vertices, inf);
  auto at = [&](int i, int j) -> double& {
    return inst->costs[static_cast<size_t>(i) * inst->num_vertices + j];
  };
  for (int u = 0; u < n; ++u) {
    if ((u & 15) == 15 && stop.ShouldStop()) return false;
    for (int v = 0; v < n; ++v) {
      const double c = model.Between(u, v);
      if (std::isfinite(c)) at(u, v) = c;
    }
    at(start, u) = model.FromStart(u);
    if (end >= 0) {
      at(u, end) = model.ToEnd(u);
    } else {
      at(u, start) = model.ToEnd(u);
    }
  }
  if (end >= 0) at(end, start) = 0.0;
  inst->sets.clear();
  for (int e = 0; e < model.num_elements(); ++e) {
    std::vector<int> set;
    for (int k = 0; k < model.num_variants(e); ++k) set.push_back(model.first_vertex(e) + k);
    inst->sets.push_back(std::move(set));
  }
  inst->sets.push_back({start});
  if (end >= 0) inst->sets.push_back({end});
  return true;
}

std::vector<int> BestRotation(const TourModel& model, const std::vector<int>& order) {
  const int m = model.num_elements();
  if (static_cast<int>(order.size()) != m || m == 0) return {};
  std::vector<char> seen(m, 0);
  for (int v : order) {
    if (v < 0 || v >= model.num_vertices() || seen[model.element_of(v)]) return {};
    seen[model.element_of(v)] = 1;
  }
  std::vector<int> reversed(order.rbegin(), order.rend());
  for (int& v : reversed) {
    const int e = model.element_of(v);
    if (model.num_variants(e) == 2) v = model.first_vertex(e) + 1 - (v - model.first_vertex(e));
  }
  // A rotation's cost is the cycle's inner arcs minus the one it cuts, plus
  // the start and end arcs at the cut: O(m) for all m rotations.
  std::vector<int> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const std::vector<int>* seq : {&order, static_cast<const std::vector<int>*>(&reversed)}) {
    const std::vector<int>& s = *seq;
    double ring = 0.0;
    for (int i = 0; i < m; ++i) ring += model.Between(s[i], s[(i + 1) % m]);
    for (int k = 0; k < m; ++k) {
      // Tour s[k], s[k+1], ..., s[k-1]: drops the arc s[k-1] -> s[k].
      const int first = s[k], last = s[(k + m - 1) % m];
      const double cut = m == 1 ? 0.0 : model.Between(last, first);
      const double cost = model.FromStart(first) + (ring - cut) + model.ToEnd(last);
      if (std::isfinite(cost) && cost < best_cost) {
        best_cost = cost;
        best.assign(s.begin() + k, s.end());
        best.insert(best.end(), s.begin(), s.begin() + k);
      }
    }
  }
  return best;
}

absl::StatusOr<TourOrder> GtspOrderer::Order(const TourModel& model, const StopToken& stop) const {
  // Warm start and fallback: the greedy tour, or the remembered order's best
  // rotation when it is cheaper.
  absl::StatusOr<TourOrder> greedy = GreedyOrderer().Order(model, stop);
  if (!greedy.ok()) return greedy.status();
  bool warm = false;
  if (!options_.warm_order.empty()) {
    std::vector<int> rotated = BestRotation(model, options_.warm_order);
    if (!rotated.empty()) {
      warm = true;
      const double cost = model.TourCost(rotated);
      if (cost <= greedy->cost) {
        greedy->vertices = std::move(rotated);
        greedy->cost = cost;
      }
    }
  }
  greedy->termination = Termination::Converged("single element: nothing to search");
  const int n = model.num_vertices();
  if (model.num_elements() <= 1) return greedy;

  const StopToken budget =
      stop.WithEarlierDeadline(absl::Now() + absl::Seconds(options_.time_limit_s));
  GtspInstance inst;
  if (!BuildGtspInstance(model, budget, &inst)) {
    greedy->stopped_early = true;
    greedy->termination = OrderTermination(true, stop, "gtsp (instance build; greedy tour kept)");
    return greedy;
  }
  const int start = n, end = model.has_end() ? n + 1 : -1;
  GtspOptions opt;
  opt.seed = options_.seed;
  opt.num_threads = options_.num_threads;
  opt.effort = options_.effort;
  opt.stop = budget;
  if (warm) {  // all trials warm: SolveGtsp skips cold trials when given an initial tour
    opt.max_trials = options_.warm_trials == OrdererOptions::kEffortTrials ? 0
                     : options_.warm_trials == 0 ? GtspOptions::kLocalStepOnly
                                                 : options_.warm_trials;
  }
  opt.initial_tour.push_back(start);
  for (int v : greedy->vertices) opt.initial_tour.push_back(v);
  if (end >= 0) opt.initial_tour.push_back(end);
  absl::StatusOr<GtspResult> result = SolveGtsp(inst, opt);
  if (!result.ok()) return result.status();

  // Rotate the cycle to begin at the start vertex; drop start/end.
  std::vector<int> cycle = result->tour;
  auto it = std::find(cycle.begin(), cycle.end(), start);
  if (it == cycle.end()) return absl::InternalError("GTSP tour misses the start vertex");
  std::rotate(cycle.begin(), it, cycle.end());
  TourOrder tour;
  for (int v : cycle) {
    if (v < n) tour.vertices.push_back(v);
  }
  tour.cost = model.TourCost(tour.vertices);
  tour.stopped_early = result->stopped_early;
  tour.termination = OrderTermination(result->stopped_early, stop, "gtsp");
  if (greedy->cost < tour.cost) {
    greedy->stopped_early = tour.stopped_early;
    greedy->termination = tour.termination;
    return greedy;
  }
  return tour;
}

}  // namespace covplan
