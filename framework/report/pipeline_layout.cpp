// Purpose: longest-path layering of the pipeline graph.
#include "pipeline_layout.hpp"

#include <algorithm>
#include <map>

namespace trackflow::report {

std::vector<NodePosition> layout_pipeline(const host::Graph& g) {
  std::vector<NodePosition> pos(g.nodes.size());
  // g.order is topological, so every input's column is final before its consumers'.
  for (int i : g.order) {
    int c = 0;
    for (int in : g.nodes[static_cast<size_t>(i)].inputs) c = std::max(c, pos[static_cast<size_t>(in)].column + 1);
    pos[static_cast<size_t>(i)].column = c;
  }
  for (size_t i = 0; i < g.nodes.size(); ++i)
    if (g.nodes[i].attach_to >= 0) pos[i].column = pos[static_cast<size_t>(g.nodes[i].attach_to)].column;
  std::map<int, int> rows;
  for (size_t i = 0; i < g.nodes.size(); ++i) pos[i].row = rows[pos[i].column]++;
  return pos;
}

}  // namespace trackflow::report
