// Purpose: parameter grids for `trackflow sweep`: parsing --param axes and enumerating the grid points (a product, or zipped axes).
#pragma once

#include <trackflow/host/config.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace trackflow::host {

// A grid larger than this is refused before any graph is built (docs/pipeline-yaml.md, "Limits").
inline constexpr std::size_t kMaxSweepPoints = 10'000;

struct SweepAxis {
  std::string node, param;
  std::vector<std::string> values;  // YAML scalars or flow lists, as written
};

// "kf.q=0.01,0.1,1" -> {kf, q, [0.01, 0.1, 1]}. Commas inside [...] or {...} do not split, so
// "radar.position=[0,0,0],[0,0,10]" has two values.
SweepAxis parse_sweep_axis(const std::string& text);

// The Cartesian product, first axis slowest: each point is one override per axis.
std::vector<std::vector<Override>> sweep_grid(const std::vector<SweepAxis>& axes);

// --zip: the axes move together, point i takes the i-th value of each (every list the same
// length): `--param kf.q=1,10 --param ukf.q=1,10 --zip` is 2 points, not 4.
std::vector<std::vector<Override>> sweep_zip(const std::vector<SweepAxis>& axes);

}  // namespace trackflow::host
