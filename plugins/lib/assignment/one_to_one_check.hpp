// Purpose: the tests' check that a returned row -> column map is one-to-one and in range (Catch2 REQUIREs).
#pragma once

#include <catch2/catch.hpp>

#include <cstddef>
#include <span>
#include <vector>

namespace trackflow::assignment::test {

// Every entry is -1 or a column in [0, cols), no column twice. Returns the number of pairs.
inline int require_one_to_one(std::span<const int> column_for_row, int cols) {
  std::vector<bool> taken(static_cast<std::size_t>(cols), false);
  int pairs = 0;
  for (const int j : column_for_row) {
    if (j == -1) continue;
    REQUIRE(j >= 0);
    REQUIRE(j < cols);
    REQUIRE_FALSE(taken[static_cast<std::size_t>(j)]);
    taken[static_cast<std::size_t>(j)] = true;
    ++pairs;
  }
  return pairs;
}

}  // namespace trackflow::assignment::test
