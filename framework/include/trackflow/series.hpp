// Purpose: a per-step table a node publishes next to its summary (ensemble series, a recorded track), with a unit per column.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace trackflow {

// One column: its name without unit ("position_rmse") and the unit in SI spelling ("m",
// "m/s", "" for a pure number). Writers put the unit into the CSV header (position_rmse_m)
// so that a file loads without guessing.
struct SeriesColumn {
  std::string name;
  std::string unit;
};

// A table of numbers, row-major; NaN marks a missing value (written as an empty cell). Nodes
// build it once in finish() from their accumulated sums, never per run or per item.
struct Series {
  std::string name;         // unique within the node, e.g. "ensemble", "truth:truth", "estimate:kf"
  std::string description;  // one line for the report and the CSV's reader
  std::vector<SeriesColumn> columns;
  std::vector<double> values;

  std::size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
  double at(std::size_t row, std::size_t col) const { return values[row * columns.size() + col]; }
  // Index of the column called `name`, or -1.
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i].name == name) return static_cast<int>(i);
    return -1;
  }
  void add_column(std::string name, std::string unit = {}) { columns.push_back({std::move(name), std::move(unit)}); }
};

}  // namespace trackflow
