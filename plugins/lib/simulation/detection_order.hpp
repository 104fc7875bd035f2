// Purpose: the order a simulated sensor gives its detections — by their values, first element first — so that the order gives nothing of their origin away.
#pragma once

#include <trackflow/items.hpp>

#include <algorithm>
#include <vector>

namespace trackflow::simulation {

// Sorts detections by value[0], then value[1], then value[2] (x, y, z or r, az, el); 2-element
// ones (planar x, y or polar r, az) by their two. All detections of one call have one size.
inline void sort_detections(std::vector<Detection>& detections) {
  std::sort(detections.begin(), detections.end(), [](const Detection& a, const Detection& b) {
    if (a.value[0] != b.value[0]) return a.value[0] < b.value[0];
    if (a.value[1] != b.value[1] || a.value.size() < 3) return a.value[1] < b.value[1];
    return a.value[2] < b.value[2];
  });
}

}  // namespace trackflow::simulation
