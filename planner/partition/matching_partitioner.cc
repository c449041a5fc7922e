#include "planner/partition/matching_partitioner.h"

#include <cstdint>
#include <utility>
#include <vector>

#include "absl/strings/str_format.h"

namespace covplan {
namespace {

constexpr int32_t kNone = -1;
constexpr int32_t kInf = INT32_MAX;
constexpr uint32_t kPollMask = (1u << 16) - 1;  // poll the stop token every 65,536 steps

// The conflict graph, implicit in the grid. Node ids are cell indices: the
// H-adjacency of cell i joins i and i + 1 (its right neighbour), the
// V-adjacency of cell i joins i and i + cols (the cell above). The
// H-adjacency of i meets the V-adjacencies of i - cols, i + 1 - cols (both
// reach down into its cells), i and i + 1; bit k of `nb[i]` says whether the
// k-th of these exists.
struct ConflictGraph {
  int32_t offset[4] = {0, 0, 0, 0};
  std::vector<uint8_t> nb;
  std::vector<int32_t> h_nodes;  // cells with an H-adjacency, in index order
  int64_t num_v = 0;
  int64_t num_free = 0;
};

ConflictGraph BuildConflictGraph(const Grid& grid) {
  ConflictGraph g;
  const int32_t cols = grid.cols();
  g.offset[0] = -cols, g.offset[1] = 1 - cols, g.offset[2] = 0, g.offset[3] = 1;
  std::vector<uint8_t> is_v(grid.size(), 0);
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      if (!grid.IsFree(r, c)) continue;
      ++g.num_free;
      if (grid.Passable(r, c, 1, 0)) is_v[grid.Index(r, c)] = 1, ++g.num_v;
    }
  }
  g.nb.assign(grid.size(), 0);
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c + 1 < grid.cols(); ++c) {
      if (!grid.Passable(r, c, 0, 1)) continue;
      const int32_t i = static_cast<int32_t>(grid.Index(r, c));
      uint8_t mask = 0;
      for (int k = r > 0 ? 0 : 2; k < 4; ++k)
        mask |= static_cast<uint8_t>(is_v[i + g.offset[k]] << k);
      g.nb[i] = mask;
      g.h_nodes.push_back(i);
    }
  }
  return g;
}

struct Matching {
  std::vector<int32_t> mate_h, mate_v;  // per cell; kNone = unmatched
  int64_t size = 0;
};

absl::Status Stopped() { return absl::DeadlineExceededError("partition stopped during matching"); }

// Each H node in index order takes its first free neighbour.
void GreedyMatching(const ConflictGraph& g, Matching& m) {
  for (int32_t h : g.h_nodes) {
    for (int k = 0; k < 4; ++k) {
      const int32_t v = h + g.offset[k];
      if ((g.nb[h] >> k & 1) && m.mate_v[v] == kNone) {
        m.mate_h[h] = v, m.mate_v[v] = h, ++m.size;
        break;
      }
    }
  }
}

// Hopcroft-Karp: per phase, layers from every free H node up to the first
// layer that meets a free V node, then vertex-disjoint shortest augmenting
// paths by depth-first search with current arcs.
absl::Status HopcroftKarp(const ConflictGraph& g, const StopToken& stop, Matching& m) {
  std::vector<int32_t> dist(m.mate_h.size(), kInf), queue, stack_h, stack_v;
  queue.reserve(g.h_nodes.size());
  std::vector<uint8_t> next_arc(m.mate_h.size(), 0);
  uint32_t steps = 0;
  auto poll = [&] { return (++steps & kPollMask) == 0 && stop.ShouldStop(); };
  while (true) {
    if (stop.ShouldStop()) return Stopped();
    queue.clear();
    for (int32_t h : g.h_nodes) {
      dist[h] = m.mate_h[h] == kNone ? 0 : kInf;
      if (dist[h] == 0) queue.push_back(h);
    }
    const size_t num_roots = queue.size();
    int32_t limit = kInf;
    for (size_t q = 0; q < queue.size(); ++q) {
      const int32_t h = queue[q];
      if (dist[h] >= limit) break;
      if (poll()) return Stopped();
      for (int k = 0; k < 4; ++k) {
        if (!(g.nb[h] >> k & 1)) continue;
        const int32_t w = m.mate_v[h + g.offset[k]];
        if (w == kNone) {
          if (limit == kInf) limit = dist[h] + 1;
        } else if (dist[w] == kInf) {
          dist[w] = dist[h] + 1;
          queue.push_back(w);
        }
      }
    }
    if (limit == kInf) return absl::OkStatus();
    for (int32_t h : queue) next_arc[h] = 0;
    // A node that fails, or lies on an augmented path, leaves the layers.
    for (size_t root = 0; root < num_roots; ++root) {
      stack_h.assign(1, queue[root]);
      stack_v.clear();
      while (!stack_h.empty()) {
        if (poll()) return Stopped();
        const int32_t h = stack_h.back();
        bool pushed = false, found = false;
        for (; next_arc[h] < 4; ++next_arc[h]) {
          const int k = next_arc[h];
          if (!(g.nb[h] >> k & 1)) continue;
          const int32_t v = h + g.offset[k], w = m.mate_v[v];
          if (w == kNone) {
            if (dist[h] + 1 == limit) {
              stack_v.push_back(v);
              found = true;
              break;
            }
          } else if (dist[w] == dist[h] + 1 && dist[w] < limit) {
            stack_v.push_back(v);
            stack_h.push_back(w);
            pushed = true;
            ++next_arc[h];
            break;
          }
        }
        if (found) {
          for (size_t l = 0; l < stack_h.size(); ++l) {
            m.mate_h[stack_h[l]] = stack_v[l], m.mate_v[stack_v[l]] = stack_h[l];
            dist[stack_h[l]] = kInf;
          }
          ++m.size;
          break;
        }
        if (!pushed) {
          dist[h] = kInf;
          stack_h.pop_back();
          if (!stack_v.empty()) stack_v.pop_back();
        }
      }
    }
  }
}

// Multi-source BFS with tree grafting (Azad, Buluç, Pothen, "Computing
// maximum cardinality matchings in parallel on bipartite graphs via
// tree-grafting", IEEE TPDS 2017), here sequential. A forest of alternating
// trees, one per free H node, every node claimed by the first tree that
// reaches it, grown breadth first; a tree stops when it meets a free V node.
// Trees are disjoint, so every tree that met one augments in the same phase,
// whatever the path lengths (Hopcroft-Karp augments only the shortest paths
// of a phase: on open fields, with few free nodes far apart, about one per
// phase). Trees that did not augment are kept whole for the next phase, and
// the nodes of augmented trees are released and grafted onto the kept trees
// they touch, so a phase searches only released ground instead of the map.
absl::Status MultiSourceBfsGraft(const ConflictGraph& g, const StopToken& stop, Matching& m) {
  const int64_t n = static_cast<int64_t>(m.mate_h.size());
  std::vector<int32_t> root_of(n, kNone);  // H node: root of its tree (kNone = in no tree)
  std::vector<int32_t> parent(n, kNone);  // V node: the H node that reached it (kNone = in no tree)
  std::vector<int32_t> leaf(n, kNone);    // root: the free V node its tree met
  std::vector<int32_t> frontier, next, tree_v, kept_v, released_v;
  for (int32_t h : g.h_nodes) {
    if (m.mate_h[h] == kNone) root_of[h] = h, frontier.push_back(h);
  }
  std::vector<int32_t> tree_h = frontier, kept_h;
  auto augmented = [&](int32_t h) { return leaf[root_of[h]] != kNone; };
  uint32_t steps = 0;
  while (true) {
    if (stop.ShouldStop()) return Stopped();
    bool any = false;
    std::vector<int32_t> roots_found;
    while (!frontier.empty()) {
      next.clear();
      for (int32_t h : frontier) {
        const int32_t root = root_of[h];
        if (leaf[root] != kNone) continue;
        if ((++steps & kPollMask) == 0 && stop.ShouldStop()) return Stopped();
        for (int k = 0; k < 4; ++k) {
          if (!(g.nb[h] >> k & 1)) continue;
          const int32_t v = h + g.offset[k];
          if (parent[v] != kNone) continue;
          parent[v] = h;
          tree_v.push_back(v);
          const int32_t w = m.mate_v[v];
          if (w == kNone) {
            leaf[root] = v, any = true;
            roots_found.push_back(root);
            break;
          }
          root_of[w] = root;  // w's only way in is its mate v, so it is in no tree yet
          tree_h.push_back(w);
          next.push_back(w);
        }
      }
      frontier.swap(next);
    }
    if (!any) return absl::OkStatus();
    for (int32_t root : roots_found) {
      for (int32_t v = leaf[root]; v != kNone;) {
        const int32_t h = parent[v], prev = m.mate_h[h];
        m.mate_h[h] = v, m.mate_v[v] = h;
        v = prev;
      }
      ++m.size;
    }
    // Release the augmented trees (their roots are matched for good).
    kept_h.clear(), kept_v.clear(), released_v.clear();
    for (int32_t v : tree_v) (augmented(parent[v]) ? released_v : kept_v).push_back(v);
    for (int32_t h : tree_h) {
      if (augmented(h)) {
        root_of[h] = kNone;
      } else {
        kept_h.push_back(h);
      }
    }
    for (int32_t v : released_v) parent[v] = kNone;
    tree_h.swap(kept_h);
    tree_v.swap(kept_v);
    if (released_v.size() > tree_v.size()) {
      // Mostly released: growing the forest afresh costs about as much as
      // grafting and lets the kept trees' ground be shared out anew.
      for (int32_t h : tree_h) root_of[h] = kNone;
      for (int32_t v : tree_v) parent[v] = kNone;
      tree_h.clear(), tree_v.clear();
      for (int32_t h : g.h_nodes) {
        if (m.mate_h[h] == kNone) root_of[h] = h, tree_h.push_back(h), frontier.push_back(h);
      }
      continue;
    }
    // Graft: a released V node next to a kept tree joins it with its mate.
    // The H nodes next to v are v + cols, v + cols - 1, v and v - 1.
    for (int32_t v : released_v) {
      for (int k = 0; k < 4; ++k) {
        const int64_t h = static_cast<int64_t>(v) - g.offset[k];
        if (h < 0 || h >= n || !(g.nb[h] >> k & 1) || root_of[h] == kNone) continue;
        const int32_t w = m.mate_v[v];  // matched: it lay in an augmented tree
        parent[v] = static_cast<int32_t>(h);
        root_of[w] = root_of[h];
        tree_v.push_back(v);
        tree_h.push_back(w);
        frontier.push_back(w);
        break;
      }
    }
  }
}

// Pothen-Fan with lookahead and fairness (PF+, Duff, Kaya, Uçar, ACM TOMS
// 2011): per phase one depth-first search from every free H node, the V
// nodes visited shared by the phase, a look at every neighbour for a free V
// node before going deeper, and the neighbour order reversed every phase.
absl::Status PothenFan(const ConflictGraph& g, const StopToken& stop, Matching& m) {
  const size_t n = m.mate_h.size();
  std::vector<int32_t> stamp_v(n, 0), stack_h, stack_v;
  std::vector<uint8_t> next_arc(n, 0), lookahead(n, 0);
  std::vector<int32_t> free_h;
  uint32_t steps = 0;
  for (int32_t phase = 1;; ++phase) {
    if (stop.ShouldStop()) return Stopped();
    free_h.clear();
    for (int32_t h : g.h_nodes) {
      if (m.mate_h[h] == kNone) free_h.push_back(h);
      next_arc[h] = 0, lookahead[h] = 0;
    }
    const bool reversed = phase % 2 == 0;
    bool any = false;
    for (int32_t root : free_h) {
      stack_h.assign(1, root);
      stack_v.clear();
      while (!stack_h.empty()) {
        if ((++steps & kPollMask) == 0 && stop.ShouldStop()) return Stopped();
        const int32_t h = stack_h.back();
        int32_t free_v = kNone;
        for (; lookahead[h] < 4 && free_v == kNone; ++lookahead[h]) {
          const int k = reversed ? 3 - lookahead[h] : lookahead[h];
          const int32_t v = h + g.offset[k];
          if ((g.nb[h] >> k & 1) && m.mate_v[v] == kNone && stamp_v[v] != phase) free_v = v;
        }
        if (free_v != kNone) {
          stamp_v[free_v] = phase;
          stack_v.push_back(free_v);
          for (size_t l = 0; l < stack_h.size(); ++l)
            m.mate_h[stack_h[l]] = stack_v[l], m.mate_v[stack_v[l]] = stack_h[l];
          ++m.size, any = true;
          break;
        }
        bool pushed = false;
        while (next_arc[h] < 4) {
          const int k = reversed ? 3 - next_arc[h] : next_arc[h];
          ++next_arc[h];
          const int32_t v = h + g.offset[k];
          if (!(g.nb[h] >> k & 1) || stamp_v[v] == phase) continue;
          stamp_v[v] = phase;
          stack_v.push_back(v);
          stack_h.push_back(m.mate_v[v]);
          pushed = true;
          break;
        }
        if (!pushed) {
          stack_h.pop_back();
          if (!stack_v.empty()) stack_v.pop_back();
        }
      }
    }
    if (!any) return absl::OkStatus();
  }
}

// König: the H nodes reachable from free H nodes by alternating paths, or
// Internal if an augmenting path is left (the matching was not maximum).
absl::StatusOr<std::vector<uint8_t>> ReachableFromFreeH(const ConflictGraph& g, const Matching& m) {
  std::vector<uint8_t> reached(m.mate_h.size(), 0);
  std::vector<int32_t> queue;
  for (int32_t h : g.h_nodes) {
    if (m.mate_h[h] == kNone) reached[h] = 1, queue.push_back(h);
  }
  for (size_t q = 0; q < queue.size(); ++q) {
    const int32_t h = queue[q];
    for (int k = 0; k < 4; ++k) {
      if (!(g.nb[h] >> k & 1)) continue;
      const int32_t w = m.mate_v[h + g.offset[k]];
      if (w == kNone)
        return absl::InternalError("matching is not maximum: an augmenting path is left");
      if (!reached[w]) reached[w] = 1, queue.push_back(w);
    }
  }
  return reached;
}

}  // namespace

absl::StatusOr<RankPartition> MatchingPartitioner::Partition(const Grid& grid,
                                                             const StopToken& stop) const {
  if (grid.size() == 0) return absl::InvalidArgumentError("grid is empty");
  if (grid.size() > INT32_MAX / 2)
    return absl::InvalidArgumentError("grid too large for the matching");
  const ConflictGraph g = BuildConflictGraph(grid);
  if (g.num_free == 0) return absl::InvalidArgumentError("grid has no free cell");
  if (stop.ShouldStop()) return absl::DeadlineExceededError("partition stopped before matching");

  Matching m;
  m.mate_h.assign(grid.size(), kNone);
  m.mate_v.assign(grid.size(), kNone);
  if (greedy_start_) GreedyMatching(g, m);
  const absl::Status solved =
      algorithm_ == MatchingAlgorithm::kHopcroftKarp ? HopcroftKarp(g, stop, m)
      : algorithm_ == MatchingAlgorithm::kPothenFan  ? PothenFan(g, stop, m)
                                                     : MultiSourceBfsGraft(g, stop, m);
  if (!solved.ok()) return solved;
  absl::StatusOr<std::vector<uint8_t>> z_h = ReachableFromFreeH(g, m);
  if (!z_h.ok()) return z_h.status();
  m.mate_h = {};
  m.mate_v = {};

  // König: Z = nodes reachable from free H nodes by alternating paths (H
  // nodes in z_h, and their V neighbours). The minimum cover is
  // (H \ Z) + (V & Z), so the kept adjacencies are H & Z and V \ Z.
  std::vector<uint8_t> v_in_z(grid.size(), 0);
  for (int32_t h : g.h_nodes) {
    if (!(*z_h)[h]) continue;
    for (int k = 0; k < 4; ++k) {
      if (g.nb[h] >> k & 1) v_in_z[h + g.offset[k]] = 1;
    }
  }
  // 1 = some kept H-adjacency holds the cell, 2 = some kept V-adjacency.
  std::vector<uint8_t> held(grid.size(), 0);
  int64_t kept = 0;
  for (int32_t h : g.h_nodes) {
    if (!(*z_h)[h]) continue;
    held[h] |= 1, held[h + 1] |= 1, ++kept;
  }
  const int32_t cols = grid.cols();
  for (int r = 0; r + 1 < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c) {
      const int32_t i = static_cast<int32_t>(grid.Index(r, c));
      if (v_in_z[i] || !grid.Passable(r, c, 1, 0)) continue;
      held[i] |= 2, held[i + cols] |= 2, ++kept;
    }
  }
  const int64_t expected_kept = static_cast<int64_t>(g.h_nodes.size()) + g.num_v - m.size;
  if (kept != expected_kept) {
    return absl::InternalError(
        absl::StrFormat("König set has %d adjacencies, expected %d", kept, expected_kept));
  }

  std::vector<uint8_t> orientation(grid.size(), 0);
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (held[i] == 3)
      return absl::InternalError("König set keeps an H and a V adjacency of one cell");
    if (held[i] == 2) orientation[i] = 1;
  }
  return CheckedPartition(grid, std::move(orientation), g.num_free - expected_kept, "matching");
}

}  // namespace covplan
