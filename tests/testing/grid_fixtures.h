// Test helpers: random grids and partition invariants shared by test files.
#ifndef COVPLAN_TESTS_TESTING_GRID_FIXTURES_H_
#define COVPLAN_TESTS_TESTING_GRID_FIXTURES_H_

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "planner/grid/grid.h"
#include "planner/partition/rank.h"

namespace covplan::testing {

// Two rows of rooms joined by doorways, with pillars: 20 x 10 cells for
// Grid::FromAscii ('.' free, '#' blocked).
inline const std::vector<std::string> kRooms = {
    "....................", "....................", "...##.......###.....", "...##.......###.....",
    "........#...........", "#######.#.##########", "........#...........", "...#................",
    "...#......##........", "..........##........",
};

// A random grid with `free_prob` free cells plus a few rectangular holes.
inline Grid RandomGrid(int rows, int cols, double free_prob, uint32_t seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution free(free_prob);
  std::vector<uint8_t> cells(static_cast<size_t>(rows) * cols);
  for (auto& c : cells) c = free(rng) ? 1 : 0;
  return Grid(rows, cols, 1.0, {0.0, 0.0}, std::move(cells));
}

// Returns an empty string when every free cell lies in exactly one rank, each
// rank is a straight run of free cells of its orientation, and no rank covers
// a blocked cell; otherwise a description of the first violation.
inline std::string CheckExactCover(const Grid& grid, const std::vector<Rank>& ranks) {
  std::vector<int> count(grid.size(), 0);
  for (size_t k = 0; k < ranks.size(); ++k) {
    const Rank& r = ranks[k];
    const bool h = r.orientation == Orientation::kHorizontal;
    if (h ? r.first.row != r.last.row || r.first.col > r.last.col
          : r.first.col != r.last.col || r.first.row > r.last.row) {
      return "rank " + std::to_string(k) + " is not a straight run";
    }
    for (int i = 0; i < r.NumCells(); ++i) {
      const int row = h ? r.first.row : r.first.row + i;
      const int col = h ? r.first.col + i : r.first.col;
      if (!grid.IsFree(row, col)) {
        return "rank " + std::to_string(k) + " covers blocked cell (" + std::to_string(row) + "," +
               std::to_string(col) + ")";
      }
      if (i > 0 && !grid.Passable(row - (h ? 0 : 1), col - (h ? 1 : 0), h ? 0 : 1, h ? 1 : 0)) {
        return "rank " + std::to_string(k) + " crosses a barrier at (" + std::to_string(row) + "," +
               std::to_string(col) + ")";
      }
      ++count[grid.Index(row, col)];
    }
  }
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (grid.free_flags()[i] && count[i] != 1) {
      CellIndex c = grid.FromIndex(i);
      return "free cell (" + std::to_string(c.row) + "," + std::to_string(c.col) + ") covered " +
             std::to_string(count[i]) + " times";
    }
  }
  return "";
}

// Independent reference for tiny grids: the fewest rank starts over every
// orientation assignment (2^free cells of them).
inline int64_t BruteForceMinRanks(const Grid& grid) {
  std::vector<int64_t> free_cells;
  for (int64_t i = 0; i < grid.size(); ++i) {
    if (grid.free_flags()[i]) free_cells.push_back(i);
  }
  int64_t best = INT64_MAX;
  std::vector<uint8_t> orient(grid.size(), 0);
  for (uint32_t mask = 0; mask < (1u << free_cells.size()); ++mask) {
    for (size_t k = 0; k < free_cells.size(); ++k) orient[free_cells[k]] = (mask >> k) & 1;
    best = std::min(best, CountRankStarts(grid, orient));
  }
  return best;
}

}  // namespace covplan::testing

#endif  // COVPLAN_TESTS_TESTING_GRID_FIXTURES_H_
