// Purpose: parsing of sweep axes and enumeration of the grid.
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/sweep.hpp>

namespace trackflow::host {

SweepAxis parse_sweep_axis(const std::string& text) {
  const Override o = parse_override(text);
  SweepAxis a{o.node, o.param, {}};
  int depth = 0;
  std::string cur;
  for (char c : o.value) {
    if (c == '[' || c == '{') ++depth;
    if (c == ']' || c == '}') --depth;
    if (c == ',' && depth == 0) {
      a.values.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  a.values.push_back(cur);
  for (auto& v : a.values) {
    const auto b = v.find_first_not_of(' '), e = v.find_last_not_of(' ');
    v = b == std::string::npos ? std::string() : v.substr(b, e - b + 1);
    if (v.empty()) throw ConfigError("--param '" + quote_token(text) + "': empty value in the list");
  }
  if (depth != 0) throw ConfigError("--param '" + quote_token(text) + "': unbalanced brackets");
  return a;
}

std::vector<std::vector<Override>> sweep_grid(const std::vector<SweepAxis>& axes) {
  std::size_t points = 1;
  for (const auto& a : axes) {
    if (a.values.size() > kMaxSweepPoints || points * a.values.size() > kMaxSweepPoints)
      throw ConfigError("the sweep grid has more than " + std::to_string(kMaxSweepPoints) +
                        " points (the product of the --param list lengths); split it into several sweeps");
    points *= a.values.size();
  }
  std::vector<std::vector<Override>> grid(1);
  for (const auto& a : axes) {
    std::vector<std::vector<Override>> next;
    for (const auto& point : grid)
      for (const auto& v : a.values) {
        auto p = point;
        p.push_back({a.node, a.param, v});
        next.push_back(std::move(p));
      }
    grid = std::move(next);
  }
  return grid;
}

std::vector<std::vector<Override>> sweep_zip(const std::vector<SweepAxis>& axes) {
  std::vector<std::vector<Override>> grid;
  if (axes.empty()) return grid;
  const std::size_t points = axes.front().values.size();
  for (const auto& a : axes)
    if (a.values.size() != points)
      throw ConfigError("--zip: every --param list must have the same length; " + axes.front().node + "." +
                        axes.front().param + " has " + std::to_string(points) + " values, " + a.node + "." + a.param +
                        " has " + std::to_string(a.values.size()));
  if (points > kMaxSweepPoints)
    throw ConfigError("the sweep has more than " + std::to_string(kMaxSweepPoints) + " points; split it into several sweeps");
  grid.resize(points);
  for (std::size_t i = 0; i < points; ++i)
    for (const auto& a : axes) grid[i].push_back({a.node, a.param, a.values[i]});
  return grid;
}

}  // namespace trackflow::host
