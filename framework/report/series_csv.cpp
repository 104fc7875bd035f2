// Purpose: CSV files of the nodes' per-step series.
#include "series_csv.hpp"

#include "csv_text.hpp"

#include <trackflow/error.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace trackflow::report {

void write_series_csv(const std::string& path, const Series& s) {
  std::string text;
  for (size_t c = 0; c < s.columns.size(); ++c)
    text += (c ? "," : "") + csv_field(column_header(s.columns[c].name, s.columns[c].unit));
  text += '\n';
  const size_t cols = s.columns.size();
  for (size_t r = 0; r < s.rows(); ++r) {
    for (size_t c = 0; c < cols; ++c) {
      if (c) text += ',';
      text += csv_number(s.values[r * cols + c]);
    }
    text += '\n';
  }
  const auto parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f << text;
  f.flush();
  if (!f) throw ConfigError("cannot write series file '" + path + "': " + std::strerror(errno));
}

std::string series_file_name(const std::string& node, const Series& s) {
  std::string name = node + "." + s.name + ".csv";
  for (char& c : name)
    if (c == ':' || c == '/' || c == '\\' || c == ' ') c = '-';
  return name;
}

std::vector<std::string> write_all_series(const std::string& dir, const host::Outcome& out) {
  std::vector<std::string> files;
  for (const auto& n : out.nodes)
    for (const auto& s : n.summary.series) {
      const std::string path = (std::filesystem::path(dir) / series_file_name(n.id, s)).string();
      write_series_csv(path, s);
      files.push_back(path);
    }
  return files;
}

}  // namespace trackflow::report
