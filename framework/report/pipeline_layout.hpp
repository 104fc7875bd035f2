// Purpose: positions of a pipeline's nodes for drawing its graph: layered left to right by data flow.
#pragma once

#include <trackflow/host/graph.hpp>

#include <vector>

namespace trackflow::report {

struct NodePosition {
  int column = 0;  // longest path from a source; adapters share their filter's column
  int row = 0;     // order within the column, in pipeline order
};

// By node index of `g`. A plain longest-path layering: pipelines are small DAGs.
std::vector<NodePosition> layout_pipeline(const host::Graph& g);

}  // namespace trackflow::report
