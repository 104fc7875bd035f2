// Purpose: vector assignment that grows storage geometrically, so that work arrays of a per-scan hot path stop allocating after a few of the largest scans.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace trackflow::memory {

// v.assign(n, value), but when n exceeds the capacity the new capacity is at least twice the old
// one. std::vector::assign allocates exactly n, so a slowly creeping maximum (one more detection
// than ever before) would allocate again and again; doubling bounds the growths to a logarithm of
// the largest size (what "no allocation once the population is steady" needs).
template <class T, class A>
void assign_grown(std::vector<T, A>& v, std::size_t n, const T& value) {
  if (n > v.capacity()) v.reserve(std::max(n, 2 * v.capacity()));
  v.assign(n, value);
}

// Capacity for at least n elements, doubling as assign_grown does (before a series of push_back).
template <class T, class A>
void reserve_grown(std::vector<T, A>& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(std::max(n, 2 * v.capacity()));
}

}  // namespace trackflow::memory
