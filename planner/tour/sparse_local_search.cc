#include "planner/tour/sparse_local_search.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_format.h"

namespace covplan {
namespace sparse_internal {

absl::Status AuditTour(int n, const std::vector<int>& t, const std::vector<int>& pos,
                       const std::vector<int>& mate, const std::vector<double>& lc, double cost) {
  const int nodes = 2 * n + 2;
  if (static_cast<int>(t.size()) != nodes || t.front() != 2 * n || t.back() != 2 * n + 1) {
    return absl::InternalError("sparse tour: the tour does not run from the start to the end");
  }
  std::vector<uint8_t> seen(nodes, 0);
  for (int i = 0; i < nodes; ++i) {
    const int v = t[i];
    if (v < 0 || v >= nodes || seen[v]) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: node %d visited twice or out of range", v));
    }
    seen[v] = 1;
    if (pos[v] != i) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: node %d is at %d, its position says %d", v, i, pos[v]));
    }
  }
  for (int i = 1; i + 1 < nodes; i += 2) {
    if (t[i + 1] != (t[i] ^ 1)) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: rank %d is not driven in one piece", t[i] / 2));
    }
  }
  double sum = 0.0;
  for (int i = 0; i < nodes; i += 2) {
    const int a = t[i], b = t[i + 1];
    if (mate[a] != b || mate[b] != a || lc[a] != lc[b]) {
      return absl::InternalError(
          absl::StrFormat("sparse tour: transition %d -> %d is not linked", a, b));
    }
    sum += lc[a];
  }
  if (!(std::abs(sum - cost) <= 1e-6 * std::max(1.0, std::abs(sum)))) {
    return absl::InternalError(absl::StrFormat(
        "sparse tour: cost %.6f s is not the sum of its transitions, %.6f s", cost, sum));
  }
  return absl::OkStatus();
}

bool SearchRun::Publish(Incumbent* shared) {
  std::lock_guard<std::mutex> lock(shared->mu);
  if (!(cost_ < shared->cost - kCostEps)) return false;
  shared->t = t_, shared->pos = pos_, shared->mate = mate_, shared->lc = lc_, shared->cost = cost_;
  version_ = shared->version.load(std::memory_order_relaxed) + 1;
  shared->version.store(version_, std::memory_order_release);
  return true;
}

void SearchRun::Sync(Incumbent* shared) {
  if (shared->version.load(std::memory_order_acquire) == version_) return;
  std::lock_guard<std::mutex> lock(shared->mu);
  t_ = shared->t, pos_ = shared->pos, mate_ = shared->mate, lc_ = shared->lc, cost_ = shared->cost;
  version_ = shared->version.load(std::memory_order_relaxed);
}

void SearchRun::CopyTour(const SearchRun& other) {
  t_ = other.t_, pos_ = other.pos_, mate_ = other.mate_, lc_ = other.lc_, cost_ = other.cost_;
}

void SearchRun::PushAll(bool reversed) {
  if (reversed) {
    for (auto it = t_.rbegin(); it != t_.rend(); ++it) Push(*it);
  } else {
    for (int v : t_) Push(v);
  }
}

void SearchRun::Rollback() {
  for (auto it = log_.rbegin(); it != log_.rend(); ++it) {
    switch (it->what) {
      case kT:
        t_[it->idx] = static_cast<int>(it->old);
        break;
      case kPos:
        pos_[it->idx] = static_cast<int>(it->old);
        break;
      case kMate:
        mate_[it->idx] = static_cast<int>(it->old);
        break;
      case kLc:
        lc_[it->idx] = it->old;
        break;
    }
  }
  log_.clear();
}

absl::Status SearchRun::Audit() const { return AuditTour(p_.n(), t_, pos_, mate_, lc_, cost_); }

absl::Status SearchRun::Construct(const StopToken& stop) {
  const int n = p_.n();
  const Grid& grid = p_.grid();
  // Bucket grid of unvisited endpoints for the fallback when every
  // candidate of the current endpoint is already visited.
  const int side = std::max(
      4, static_cast<int>(std::sqrt(static_cast<double>(grid.size()) / std::max(1, 2 * n))));
  const int brows = grid.rows() / side + 1, bcols = grid.cols() / side + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(brows) * bcols);
  for (int e = 0; e < 2 * n; ++e) {
    const CellIndex c = p_.cell(e);
    buckets[static_cast<size_t>(c.row / side) * bcols + c.col / side].push_back(e);
  }
  std::vector<uint8_t> visited(n, 0);
  t_.clear();
  t_.push_back(p_.S());
  int cur = p_.S();
  std::vector<std::pair<double, int>> near;
  for (int step = 0; step < n; ++step) {
    if ((step & 255) == 255 && stop.cancelled())
      return absl::CancelledError("tour construction cancelled");
    int best = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    const absl::Span<const EndpointCandidate> cands = p_.candidates(cur);
    for (size_t i = 0; i < cands.size(); ++i) {
      if (visited[cands[i].endpoint / 2]) continue;
      const double cost = p_.CandidateCost(cur, i);
      if (cost < best_cost) best_cost = cost, best = cands[i].endpoint;
    }
    if (best < 0) {
      // Nearest unvisited endpoints by lower bound, ring by ring.
      const CellIndex at = p_.cell(cur);
      const int br = at.row / side, bc = at.col / side;
      near.clear();
      constexpr size_t kWant = 8;
      for (int r = 0; r <= std::max(brows, bcols); ++r) {
        for (int rr = br - r; rr <= br + r; ++rr) {
          if (rr < 0 || rr >= brows) continue;
          for (int cc = bc - r; cc <= bc + r; ++cc) {
            if (cc < 0 || cc >= bcols) continue;
            if (std::max(std::abs(rr - br), std::abs(cc - bc)) != r) continue;
            std::vector<int>& b = buckets[static_cast<size_t>(rr) * bcols + cc];
            for (size_t i = 0; i < b.size();) {
              if (visited[b[i] / 2]) {
                b[i] = b.back();
                b.pop_back();
                continue;
              }
              const double lb = L(cur, b[i]);
              if (std::isfinite(lb)) near.push_back({lb, b[i]});
              ++i;
            }
          }
        }
        if (near.size() >= kWant) {
          std::nth_element(near.begin(), near.begin() + (kWant - 1), near.end());
          // Endpoints beyond ring r are at least r * side cells away.
          if (p_.StraightCost(static_cast<float>(r * side)) >= near[kWant - 1].first) break;
        }
      }
      // Exact searches are the expensive part: price the two best by bound.
      std::sort(near.begin(), near.end());
      for (size_t i = 0; i < near.size() && i < 2; ++i) {
        if (near[i].first >= best_cost) break;
        const double cost = C(cur, near[i].second);
        if (cost < best_cost) best_cost = cost, best = near[i].second;
      }
      if (best < 0) {
        return absl::InvalidArgumentError(
            absl::StrFormat("rank %d cannot be reached from the start pose", [&] {
              for (int k = 0; k < n; ++k) {
                if (!visited[k]) return k;
              }
              return -1;
            }()));
      }
    }
    visited[best / 2] = 1;
    t_.push_back(best);
    t_.push_back(best ^ 1);
    cur = best ^ 1;
  }
  t_.push_back(p_.E());
  PriceTour();
  return absl::OkStatus();
}

void SearchRun::PriceTour() {
  cost_ = 0.0;
  for (size_t i = 0; i < t_.size(); ++i) pos_[t_[i]] = static_cast<int>(i);
  for (size_t i = 0; i + 1 < t_.size(); i += 2) {
    const double c = C(t_[i], t_[i + 1]);
    Link(t_[i], t_[i + 1], c);
    cost_ += c;
  }
}

bool SearchRun::ConstructFrom(const std::vector<int>& order) {
  const int n = p_.n();
  if (static_cast<int>(order.size()) != n || n == 0) return false;
  std::vector<uint8_t> seen(n, 0);
  for (int v : order) {
    if (v < 0 || v >= 2 * n || seen[v / 2]) return false;
    seen[v / 2] = 1;
  }
  // Entry of the k-th rank in direction d (0: as remembered, 1: reversed).
  auto entry = [&](int d, int k) { return d == 0 ? order[k] : order[n - 1 - k] ^ 1; };
  int best_d = 0, best_r = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 2; ++d) {
    for (int r = 0; r < n; ++r) {
      const int in = entry(d, r), out = entry(d, (r + n - 1) % n) ^ 1;
      const double c = L(p_.S(), in) + L(out, p_.E()) - (n > 1 ? L(out, in) : 0.0);
      if (c < best) best = c, best_d = d, best_r = r;
    }
  }
  t_.clear();
  t_.push_back(p_.S());
  for (int k = 0; k < n; ++k) {
    const int e = entry(best_d, (best_r + k) % n);
    t_.push_back(e);
    t_.push_back(e ^ 1);
  }
  t_.push_back(p_.E());
  PriceTour();
  return true;
}

void SearchRun::ApplyTwoOpt(int i, int j, double c1, double c2) {
  // Reverse t[i+1..j]; the new edges are (t[i], old t[j]) and (old t[i+1], t[j+1]).
  const int a = t_[i], b = t_[i + 1], c = t_[j], d = t_[j + 1];
  for (int lo = i + 1, hi = j; lo < hi; ++lo, --hi) {
    const int x = t_[lo], y = t_[hi];
    SetT(lo, y);
    SetT(hi, x);
  }
  Link(a, c, c1);
  Link(b, d, c2);
}

bool SearchRun::TryTwoOpt(int i, int j) {
  if (i > j) std::swap(i, j);
  if (j - i < 2 || i < 0 || j + 1 >= static_cast<int>(t_.size())) return false;
  const int a = t_[i], b = t_[i + 1], c = t_[j], d = t_[j + 1];
  const double removed = lc_[a] + lc_[c];
  const double lac = L(a, c), lbd = L(b, d);
  if (lac + lbd >= removed - kCostEps) return false;
  double c1, c2;
  // The pair known without a search first, so the bound can spare the other.
  if (p_.Known(b, d) && !p_.Known(a, c)) {
    c2 = C(b, d);
    if (B(a, c) + c2 >= removed - kCostEps) return false;
    c1 = C(a, c);
  } else {
    c1 = B(a, c);
    if (c1 + lbd >= removed - kCostEps) return false;
    if (B(b, d) + c1 >= removed - kCostEps) return false;
    c1 = C(a, c);
    if (c1 + lbd >= removed - kCostEps) return false;
    c2 = C(b, d);
  }
  if (c1 + c2 >= removed - kCostEps) return false;
  cost_ += c1 + c2 - removed;
  ApplyTwoOpt(i, j, c1, c2);
  for (int v : {a, b, c, d}) Push(v);
  return true;
}

void SearchRun::ApplyOrOpt(int a, int b, int k, bool reversed, double gap, double cl, double cr) {
  const int before = t_[a - 1], after = t_[b + 1], left = t_[2 * k], right = t_[2 * k + 1];
  scratch_.assign(t_.begin() + a, t_.begin() + b + 1);
  if (reversed) std::reverse(scratch_.begin(), scratch_.end());
  const int first = scratch_.front(), last = scratch_.back();
  if (2 * k + 1 < a) {
    // Insert before: [2k+1, b] becomes seg + old [2k+1, a-1].
    std::vector<int> moved(t_.begin() + 2 * k + 1, t_.begin() + a);
    int w = 2 * k + 1;
    for (int v : scratch_) SetT(w++, v);
    for (int v : moved) SetT(w++, v);
  } else {
    // Insert after: [a, 2k] becomes old [b+1, 2k] + seg.
    std::vector<int> moved(t_.begin() + b + 1, t_.begin() + 2 * k + 1);
    int w = a;
    for (int v : moved) SetT(w++, v);
    for (int v : scratch_) SetT(w++, v);
  }
  Link(before, after, gap);
  Link(left, first, cl);
  Link(last, right, cr);
}

bool SearchRun::TryOrOpt(int a, int b, int k, bool reversed) {
  const int size = static_cast<int>(t_.size());
  if (a < 1 || b + 1 >= size || k < 0 || 2 * k + 1 >= size) return false;
  if (!(2 * k + 1 < a - 1 || 2 * k > b)) return false;  // not next to or inside the segment
  const int before = t_[a - 1], after = t_[b + 1], left = t_[2 * k], right = t_[2 * k + 1];
  const int first = reversed ? t_[b] : t_[a], last = reversed ? t_[a] : t_[b];
  const double removed = lc_[before] + lc_[t_[b]] + lc_[left];
  const double lg = L(before, after), ll = L(left, first), lr = L(last, right);
  if (lg + ll + lr >= removed - kCostEps) return false;
  // Known pairs first (no search), then the rest while the bound allows.
  double cost[3] = {lg, ll, lr};
  const int xs[3] = {before, left, last}, ys[3] = {after, first, right};
  // Known pairs first, otherwise in edge order (a stable partition of three).
  int order[3];
  bool known[3];
  for (int e = 0; e < 3; ++e) known[e] = p_.Known(xs[e], ys[e]);
  int filled = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int e = 0; e < 3; ++e) {
      if (known[e] == (pass == 0)) order[filled++] = e;
    }
  }
  for (int o : order) {
    cost[o] = B(xs[o], ys[o]);
    if (cost[0] + cost[1] + cost[2] >= removed - kCostEps) return false;
  }
  for (int o : order) {
    cost[o] = C(xs[o], ys[o]);
    if (cost[0] + cost[1] + cost[2] >= removed - kCostEps) return false;
  }
  const double cg = cost[0], cl = cost[1], cr = cost[2];
  cost_ += cg + cl + cr - removed;
  ApplyOrOpt(a, b, k, reversed, cg, cl, cr);
  for (int v : {before, after, left, right, first, last}) Push(v);
  return true;
}

bool SearchRun::Improve(int x) {
  const int p = pos_[x];
  const int last_pos = static_cast<int>(t_.size()) - 1;
  // 2-opt: a new transition edge (x, y) for a candidate y.
  const absl::Span<const EndpointCandidate> cands = p_.candidates(x);
  for (size_t ci = 0; ci < cands.size(); ++ci) {
    const int y = cands[ci].endpoint;
    const int q = pos_[y];
    if ((q & 1) != (p & 1) || q == p) continue;
    if (x != p_.E() && p_.CandidateCost(x, ci) >= lc_[x] - kCostEps)
      continue;  // no gain on x's side
    const int i = (p & 1) ? std::min(p, q) - 1 : std::min(p, q);
    const int j = (p & 1) ? std::max(p, q) - 1 : std::max(p, q);
    if (TryTwoOpt(i, j)) return true;
  }
  if (x >= p_.S()) return false;
  // Runs of 1-3 ranks starting (x an entry) or ending (x an exit) at x:
  // reverse in place, or move next to a candidate of either end.
  for (int len = 1; len <= 3; ++len) {
    int a, b;
    if (p & 1) {
      a = p, b = p + 2 * len - 1;
    } else {
      b = p, a = p - 2 * len + 1;
    }
    if (a < 1 || b >= last_pos) break;
    if (TryTwoOpt(a - 1, b)) return true;
    for (int end = 0; end < 2; ++end) {
      const int z = t_[end == 0 ? a : b];
      for (const EndpointCandidate& c : p_.candidates(z)) {
        const int q = pos_[c.endpoint];
        if (q >= a - 1 && q <= b + 1) continue;
        int k;
        bool reversed;
        if (end == 0) {
          // (y, first): after an exit y forwards; before an entry y reversed.
          if ((q & 1) == 0)
            k = q / 2, reversed = false;
          else
            k = (q - 1) / 2, reversed = true;
        } else {
          if (q & 1)
            k = (q - 1) / 2, reversed = false;
          else
            k = q / 2, reversed = true;
        }
        if (TryOrOpt(a, b, k, reversed)) return true;
      }
    }
  }
  return false;
}

void SearchRun::LocalSearch(const StopToken& stop) {
  stop_ = &stop;
  int64_t pops = 0;
  while (!queue_.empty()) {
    if ((++pops & 15) == 0 && stop.ShouldStop()) break;
    const int x = queue_.front();
    queue_.pop_front();
    queued_[x] = 0;
    if (Improve(x)) Push(x);
  }
  for (int v : queue_) queued_[v] = 0;
  queue_.clear();
  stop_ = &never_;
}

void SearchRun::DoubleBridge(int i, int j, int k) {
  // [.., t[i]] [t[i+1] .. t[j]] [t[j+1] .. t[k]] [t[k+1] ..]  ->  A C B D.
  const int a = t_[i], b1 = t_[i + 1], b2 = t_[j], c1 = t_[j + 1], c2 = t_[k], d = t_[k + 1];
  const double removed = lc_[a] + lc_[b2] + lc_[c2];
  const double x = C(a, c1), y = C(c2, b1), z = C(b2, d);
  std::vector<int> seg(t_.begin() + j + 1, t_.begin() + k + 1);
  seg.insert(seg.end(), t_.begin() + i + 1, t_.begin() + j + 1);
  for (size_t m = 0; m < seg.size(); ++m) SetT(i + 1 + static_cast<int>(m), seg[m]);
  Link(a, c1, x);
  Link(c2, b1, y);
  Link(b2, d, z);
  cost_ += x + y + z - removed;
  for (int v : {a, b1, b2, c1, c2, d}) Push(v);
}

bool SearchRun::Iterate(const StopToken& stop, int64_t converge_after, bool until_limit,
                        Incumbent* shared) {
  const int n = p_.n();
  if (n < 4) return true;
  std::atomic<int64_t> own_stale{0};
  std::atomic<int64_t>& no_improve = shared != nullptr ? shared->stale : own_stale;
  while (!stop.ShouldStop()) {
    if (!until_limit && no_improve.load(std::memory_order_relaxed) >= converge_after) return true;
    if (shared != nullptr) Sync(shared);
    // A local double bridge A B C D -> A C B D at the transition edge
    // (t[i], t[i+1]) of a random endpoint: t[j+1] a candidate of t[i] and
    // t[k] a candidate of t[i+1] when the tour order allows, so two of the
    // three new edges are candidate pairs (no search) between close
    // endpoints; else the edges of two candidates of candidates.
    const int x = static_cast<int>(rng_.UniformInt(2 * n));
    auto pick = [&](int from) {
      absl::Span<const EndpointCandidate> c = p_.candidates(from);
      return c.empty() ? static_cast<int>(rng_.UniformInt(2 * n))
                       : c[rng_.UniformInt(static_cast<int>(c.size()))].endpoint;
    };
    const int i0 = pos_[x] & ~1;  // left end of x's transition edge
    int i = -1, j = -1, k = -1;
    for (int attempt = 0; attempt < 4 && i < 0; ++attempt) {
      const int q = pos_[pick(t_[i0])];
      if ((q & 1) == 0 || q < i0 + 3) continue;
      const int r = pos_[pick(t_[i0 + 1])];
      if ((r & 1) != 0 || r < q + 1) continue;
      i = i0, j = q - 1, k = r;
    }
    if (i < 0) {
      const int y = pick(x);
      const int z = pick(y);
      int e[3] = {i0, pos_[y] & ~1, pos_[z] & ~1};
      std::sort(e, e + 3);
      if (e[0] == e[1] || e[1] == e[2] || e[2] + 1 >= static_cast<int>(t_.size())) {
        ++no_improve;
        continue;
      }
      i = e[0], j = e[1], k = e[2];
    }
    const double saved = cost_;
    ++kicks_;
    logging_ = true;
    stop_ = &stop;
    DoubleBridge(i, j, k);
    LocalSearch(stop);
    logging_ = false;
    if (cost_ < saved - kCostEps && std::isfinite(cost_)) {
      log_.clear();
      // Shared: a gain counts once it beats the incumbent (another thread
      // may have published a better tour meanwhile; the next kick takes it).
      if (shared == nullptr || Publish(shared)) {
        no_improve = 0;
      } else {
        ++no_improve;
      }
    } else {
      Rollback();
      cost_ = saved;
      ++no_improve;
    }
  }
  return false;
}

}  // namespace sparse_internal
}  // namespace covplan
