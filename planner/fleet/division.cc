#include "planner/fleet/division.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <utility>

#include "planner/tour/grid_paths.h"

namespace covplan {
namespace {

constexpr int kDr[4] = {1, -1, 0, 0};
constexpr int kDc[4] = {0, 0, 1, -1};

// Greedy pieces within makespan `t` for robots in `order`, the tour cut at
// unit `from`; false when units are left over. Each robot takes the longest
// run it finishes within t.
bool GreedyPieces(const UnitCosts& costs, const std::vector<int>& order, int from, double t,
                  std::vector<std::pair<int, int>>* pieces) {
  const int end = from + costs.num_units();
  int i = from;
  for (int r : order) {
    int best = i - 1;
    const double s = costs.scale(r);
    for (int j = i; j < end; ++j) {
      if (s * costs.Along(r, i, j) > t) break;
      if (costs.Piece(r, i, j) <= t) best = j;
    }
    if (pieces != nullptr) (*pieces)[r] = {i, best};
    i = best + 1;
  }
  return i >= end;
}

// The smallest makespan GreedyPieces meets for `order` and `from` (binary
// search up to `hi`); +inf when even `hi` is not met.
double SplitOrder(const UnitCosts& costs, const std::vector<int>& order, int from, double hi,
                  std::vector<std::pair<int, int>>* pieces) {
  if (!GreedyPieces(costs, order, from, hi, nullptr)) return INFINITY;
  double lo = 0.0;
  for (int it = 0; it < 30 && hi - lo > 1e-3 * std::max(1.0, hi); ++it) {
    const double mid = 0.5 * (lo + hi);
    (GreedyPieces(costs, order, from, mid, nullptr) ? hi : lo) = mid;
  }
  GreedyPieces(costs, order, from, hi, pieces);
  double worst = 0.0;
  for (int r : order) {
    const auto [a, b] = (*pieces)[r];
    if (a <= b) worst = std::max(worst, costs.Piece(r, a, b));
  }
  return worst;
}

}  // namespace

TourSplit SplitTour(const UnitCosts& costs) {
  const int k = costs.num_robots();
  const int n = costs.num_units();
  TourSplit best;
  best.pieces.assign(k, {0, -1});
  best.order.resize(k);
  std::iota(best.order.begin(), best.order.end(), 0);
  if (n == 0 || k == 0) return best;
  best.estimate_s = INFINITY;
  double hi = 0.0;  // any robot alone: an upper bound while finite
  for (int r = 0; r < k; ++r) {
    const double all = costs.Piece(r, 0, n - 1);
    if (std::isfinite(all)) hi = std::max(hi, all);
  }
  hi = 2.0 * std::max(hi, 1.0);
  // Splits within 1 % of the best makespan are told apart by the robots'
  // summed time: the trips from the starts count there, so of two splits
  // that finish alike the one whose robots stay nearer home (compact
  // regions, no criss-crossing) wins.
  double best_sum = INFINITY;
  auto summed = [&](const std::vector<std::pair<int, int>>& pieces) {
    double sum = 0.0;
    for (int r = 0; r < k; ++r) {
      if (pieces[r].first <= pieces[r].second)
        sum += costs.Piece(r, pieces[r].first, pieces[r].second);
    }
    return sum;
  };
  auto consider = [&](const std::vector<int>& order, int from) {
    std::vector<std::pair<int, int>> pieces(k, {0, -1});
    const double m = SplitOrder(costs, order, from, hi, &pieces);
    if (!std::isfinite(m)) return m;
    const double sum = summed(pieces);
    if (m < 0.99 * best.estimate_s || (m <= 1.01 * best.estimate_s && sum < best_sum)) {
      best = {order, std::move(pieces), m};
      best_sum = sum;
    }
    return m;
  };
  // Where the cycle is cut: evenly spaced units and the unit nearest each
  // robot's start, at most 32 in all.
  std::vector<int> anchor(k, 0);
  for (int r = 0; r < k; ++r) {
    double nearest = INFINITY;
    for (int u = 0; u < n; ++u) {
      if (costs.Reach(r, u) < nearest) nearest = costs.Reach(r, u), anchor[r] = u;
    }
  }
  std::vector<int> cuts(anchor.begin(), anchor.end());
  const int even = std::min(n, std::max(1, 32 - k));
  for (int i = 0; i < even; ++i)
    cuts.push_back(static_cast<int>(static_cast<int64_t>(i) * n / even));
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  // The robots in the order their anchors follow the cut.
  auto anchored = [&](int from) {
    std::vector<int> order(k);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return (anchor[a] - from + n) % n < (anchor[b] - from + n) % n;
    });
    return order;
  };
  double perms = 1.0;
  for (int i = 2; i <= k; ++i) perms *= i;
  if (perms * n * cuts.size() <= 4e5) {  // every order at every cut
    for (int from : cuts) {
      std::vector<int> p(k);
      std::iota(p.begin(), p.end(), 0);
      do consider(p, from);
      while (std::next_permutation(p.begin(), p.end()));
    }
    return best;
  }
  // Else the anchored order at every cut, then neighbour swaps at the best.
  int best_from = cuts[0];
  double best_m = INFINITY;
  for (int from : cuts) {
    const double m = consider(anchored(from), from);
    if (m < best_m) best_m = m, best_from = from;
  }
  std::vector<int> order = anchored(best_from);
  double current = best_m;
  for (int pass = 0, improved = 1; improved && pass < 4; ++pass) {
    improved = 0;
    for (int i = 0; i + 1 < k; ++i) {
      std::swap(order[i], order[i + 1]);
      const double m = consider(order, best_from);
      if (m < current - 1e-9) {
        current = m;
        improved = 1;
      } else {
        std::swap(order[i], order[i + 1]);
      }
    }
  }
  return best;
}

std::vector<std::vector<int64_t>> CellsOfSplit(const TourUnits& units, const TourSplit& split) {
  std::vector<std::vector<int64_t>> cells(split.pieces.size());
  for (size_t r = 0; r < split.pieces.size(); ++r) {
    for (int u = split.pieces[r].first; u <= split.pieces[r].second; ++u) {
      const auto& c = units.units[u % units.units.size()].cells;
      cells[r].insert(cells[r].end(), c.begin(), c.end());
    }
  }
  return cells;
}

namespace {

// Seeds for robots without a start: the cover cell farthest (straight-line)
// from the seeds chosen so far, the first near the cover's centroid.
std::vector<int64_t> SpreadSeeds(const Grid& cover, int count) {
  std::vector<int64_t> cells;
  double cx = 0.0, cy = 0.0;
  for (int64_t i = 0; i < cover.size(); ++i) {
    if (!cover.free_flags()[i]) continue;
    cells.push_back(i);
    const CellIndex c = cover.FromIndex(i);
    cx += c.col, cy += c.row;
  }
  std::vector<int64_t> seeds;
  if (cells.empty()) return seeds;
  cx /= cells.size(), cy /= cells.size();
  std::vector<double> d(cells.size());
  for (size_t j = 0; j < cells.size(); ++j) {
    const CellIndex c = cover.FromIndex(cells[j]);
    d[j] = -std::hypot(c.col - cx, c.row - cy);  // first: nearest the centroid
  }
  for (int s = 0; s < count; ++s) {
    const size_t pick = std::max_element(d.begin(), d.end()) - d.begin();
    seeds.push_back(cells[pick]);
    const CellIndex p = cover.FromIndex(cells[pick]);
    for (size_t j = 0; j < cells.size(); ++j) {
      const CellIndex c = cover.FromIndex(cells[j]);
      const double dist = std::hypot(c.col - p.col, c.row - p.row);
      d[j] = s == 0 ? dist : std::min(d[j], dist);
    }
  }
  return seeds;
}

// True when cell i can leave its region without cutting it locally: the
// region's cells among its 8 neighbours (in ring order) form at most one run
// that holds a 4-neighbour, so every path through i can go around it.
bool KeepsRegionConnected(const Grid& drive, const std::vector<int>& owner, int64_t i) {
  static constexpr int kRingDr[8] = {1, 1, 0, -1, -1, -1, 0, 1};
  static constexpr int kRingDc[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  const CellIndex c = drive.FromIndex(i);
  bool in[8];
  for (int j = 0; j < 8; ++j) {
    const int r = c.row + kRingDr[j], col = c.col + kRingDc[j];
    in[j] = drive.InBounds(r, col) && owner[drive.Index(r, col)] == owner[i];
  }
  int runs = 0;
  bool all = true;
  for (int j = 0; j < 8; ++j) {
    all &= in[j];
    if (!in[j] || in[(j + 7) % 8]) continue;  // not the start of a run
    bool orthogonal = false;
    for (int m = j; m < j + 8 && in[m % 8]; ++m) orthogonal |= (m % 8) % 2 == 0;
    runs += orthogonal;
  }
  return all || runs <= 1;
}

// Evens out the loads (the summed cell costs) of regions grown unevenly (a
// robot boxed in by the others): the most loaded region hands the cells
// along its border with its least loaded neighbour over to it, up to half
// the difference at a time, while that narrows the spread.
void BalanceRegions(const Grid& drive, int k, const std::vector<double>& cost,
                    std::vector<int>* owner_ptr) {
  std::vector<int>& owner = *owner_ptr;
  std::vector<double> load(k, 0.0);
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (owner[i] >= 0) load[owner[i]] += cost[i];
  }
  std::vector<uint8_t> stuck(k, 0);
  for (int round = 0; round < 64 * k; ++round) {
    int big = -1;
    for (int r = 0; r < k; ++r) {
      if (!stuck[r] && (big < 0 || load[r] > load[big])) big = r;
    }
    if (big < 0) break;
    // Its border cells, by neighbour.
    std::vector<std::vector<int64_t>> border(k);
    for (int64_t i = 0; i < drive.size(); ++i) {
      if (owner[i] != big) continue;
      const CellIndex c = drive.FromIndex(i);
      for (int m = 0; m < 4; ++m) {
        if (!drive.Passable(c.row, c.col, kDr[m], kDc[m])) continue;
        const int o = owner[drive.Index(c.row + kDr[m], c.col + kDc[m])];
        if (o >= 0 && o != big && (border[o].empty() || border[o].back() != i)) {
          border[o].push_back(i);
        }
      }
    }
    int small = -1;
    for (int r = 0; r < k; ++r) {
      if (!border[r].empty() && load[r] < load[big] && (small < 0 || load[r] < load[small]))
        small = r;
    }
    if (small < 0) {
      stuck[big] = 1;
      continue;
    }
    // Hand over border cells whose loss leaves `big` connected around them,
    // up to half the difference (no further: the two would swap places).
    const double want = (load[big] - load[small]) / 2.0;
    double given = 0.0;
    for (int64_t i : border[small]) {
      if (given + cost[i] > want) break;
      if (!KeepsRegionConnected(drive, owner, i)) continue;
      owner[i] = small;
      given += cost[i];
    }
    load[big] -= given;
    load[small] += given;
    if (given == 0.0) {
      stuck[big] = 1;
      continue;
    }
    std::fill(stuck.begin(), stuck.end(), 0);
  }
}

}  // namespace

std::vector<std::vector<int64_t>> EqualAreaRegions(
    const Grid& drive, const Grid& cover, const std::vector<std::optional<Pose2>>& starts) {
  return BalancedRegions(drive, cover, starts, std::vector<double>(drive.size(), 1.0));
}

std::vector<std::vector<int64_t>> BalancedRegions(const Grid& drive, const Grid& cover,
                                                  const std::vector<std::optional<Pose2>>& starts,
                                                  const std::vector<double>& cost) {
  const int k = static_cast<int>(starts.size());
  std::vector<std::vector<int64_t>> regions(k);
  if (k == 0) return regions;
  const int64_t total = cover.CountFree();
  double total_cost = 0.0;
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (cover.free_flags()[i]) total_cost += cost[i];
  }
  const double quota = total_cost / k;
  int unseeded = 0;
  for (const auto& s : starts) unseeded += !s.has_value();
  const std::vector<int64_t> spread = SpreadSeeds(cover, unseeded);
  std::vector<int> owner(static_cast<size_t>(drive.size()), -1);
  using Entry = std::pair<double, int64_t>;
  std::vector<std::priority_queue<Entry, std::vector<Entry>, std::greater<>>> open(k);
  std::vector<std::vector<double>> dist(k);
  int next_spread = 0;
  for (int r = 0; r < k; ++r) {
    int64_t seed = -1;
    if (starts[r].has_value()) {
      absl::StatusOr<CellIndex> c = JoinCell(drive, *starts[r], "start");
      if (c.ok()) seed = drive.Index(c->row, c->col);
    } else if (next_spread < static_cast<int>(spread.size())) {
      seed = spread[next_spread++];
    }
    if (seed < 0) continue;
    dist[r].assign(static_cast<size_t>(drive.size()), INFINITY);
    dist[r][seed] = 0.0;
    open[r].push({0.0, seed});
  }
  // In turns, each robot under its quota claims its nearest unclaimed cover
  // cell; it grows through free cells no other robot has claimed.
  std::vector<double> claimed(k, 0.0);
  int64_t left = total;
  for (bool progress = true; left > 0 && progress;) {
    progress = false;
    for (int r = 0; r < k && left > 0; ++r) {
      if (claimed[r] >= quota) continue;
      while (!open[r].empty()) {
        const auto [d, i] = open[r].top();
        open[r].pop();
        if (d > dist[r][i] || (owner[i] >= 0 && owner[i] != r)) continue;
        const CellIndex c = drive.FromIndex(i);
        for (int m = 0; m < 4; ++m) {
          if (!drive.Passable(c.row, c.col, kDr[m], kDc[m])) continue;
          const int64_t j = drive.Index(c.row + kDr[m], c.col + kDc[m]);
          if (owner[j] >= 0 && owner[j] != r) continue;
          if (d + 1.0 < dist[r][j]) dist[r][j] = d + 1.0, open[r].push({d + 1.0, j});
        }
        if (owner[i] < 0 && cover.free_flags()[i]) {
          owner[i] = r;
          claimed[r] += cost[i];
          --left;
          progress = true;
          break;
        }
        if (owner[i] < 0) owner[i] = -2 - r;  // passed through, not a cell to cover
      }
    }
  }
  // Cover cells no region reached (its robots at quota): the nearest region.
  std::queue<int64_t> queue;
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (owner[i] >= 0) queue.push(i);
  }
  while (!queue.empty()) {
    const int64_t i = queue.front();
    queue.pop();
    const CellIndex c = drive.FromIndex(i);
    for (int m = 0; m < 4; ++m) {
      if (!drive.Passable(c.row, c.col, kDr[m], kDc[m])) continue;
      const int64_t j = drive.Index(c.row + kDr[m], c.col + kDc[m]);
      if (owner[j] >= 0) continue;
      owner[j] = owner[i];
      queue.push(j);
    }
  }
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (owner[i] >= 0 && !cover.free_flags()[i]) owner[i] = -1;
  }
  BalanceRegions(drive, k, cost, &owner);
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (owner[i] >= 0) regions[owner[i]].push_back(i);
  }
  return regions;
}

int64_t MakeRegionsConnected(const Grid& drive, std::vector<std::vector<int64_t>>* cells) {
  const int k = static_cast<int>(cells->size());
  std::vector<int> owner(static_cast<size_t>(drive.size()), -1);
  for (int r = 0; r < k; ++r) {
    for (int64_t i : (*cells)[r]) owner[i] = r;
  }
  int64_t moved = 0;
  for (int round = 0; round < 4 * k + 4; ++round) {
    // Components of equal owner.
    std::vector<int32_t> comp(owner.size(), -1);
    std::vector<int64_t> size;
    std::vector<int> comp_owner;
    for (int64_t s = 0; s < drive.size(); ++s) {
      if (owner[s] < 0 || comp[s] >= 0) continue;
      const int32_t id = static_cast<int32_t>(size.size());
      size.push_back(0);
      comp_owner.push_back(owner[s]);
      std::vector<int64_t> stack{s};
      comp[s] = id;
      while (!stack.empty()) {
        const int64_t i = stack.back();
        stack.pop_back();
        ++size[id];
        const CellIndex c = drive.FromIndex(i);
        for (int m = 0; m < 4; ++m) {
          if (!drive.Passable(c.row, c.col, kDr[m], kDc[m])) continue;
          const int64_t j = drive.Index(c.row + kDr[m], c.col + kDc[m]);
          if (owner[j] == owner[s] && comp[j] < 0) comp[j] = id, stack.push_back(j);
        }
      }
    }
    std::vector<int32_t> largest(k, -1);
    for (size_t id = 0; id < size.size(); ++id) {
      int32_t& l = largest[comp_owner[id]];
      if (l < 0 || size[id] > size[l]) l = static_cast<int32_t>(id);
    }
    // Each stray component goes to the region it touches most.
    bool changed = false;
    std::vector<std::vector<int64_t>> members(size.size());
    for (int64_t i = 0; i < drive.size(); ++i) {
      if (comp[i] >= 0 && comp[i] != largest[owner[i]]) members[comp[i]].push_back(i);
    }
    for (size_t id = 0; id < size.size(); ++id) {
      if (members[id].empty()) continue;
      std::vector<int64_t> touch(k, 0);
      for (int64_t i : members[id]) {
        const CellIndex c = drive.FromIndex(i);
        for (int m = 0; m < 4; ++m) {
          if (!drive.Passable(c.row, c.col, kDr[m], kDc[m])) continue;
          const int o = owner[drive.Index(c.row + kDr[m], c.col + kDc[m])];
          if (o >= 0 && o != comp_owner[id]) ++touch[o];
        }
      }
      const int to = static_cast<int>(std::max_element(touch.begin(), touch.end()) - touch.begin());
      if (touch[to] == 0) continue;  // touches no other region: stays
      for (int64_t i : members[id]) owner[i] = to;
      moved += static_cast<int64_t>(members[id].size());
      changed = true;
    }
    if (!changed) break;
  }
  for (auto& c : *cells) c.clear();
  for (int64_t i = 0; i < drive.size(); ++i) {
    if (owner[i] >= 0) (*cells)[owner[i]].push_back(i);
  }
  return moved;
}

}  // namespace covplan
