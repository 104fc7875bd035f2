// Purpose: CSV files of the nodes' per-step series.
#include "series_csv.hpp"

#include "csv_text.hpp"

#include <trackflow/error.hpp>
#include <trackflow/safe_output.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace trackflow::report {

namespace {
std::string series_text(const Series& s) {
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
  return text;
}

// A temporary renamed into place (safe_output.hpp): a full disk leaves no truncated series file.
void fail_series(const SafeOutputFile& f) {
  throw ConfigError("cannot write series file '" + f.path() + "': " + std::strerror(f.error_number()));
}
}  // namespace

void write_series_csv(const std::string& path, const Series& s) {
  SafeOutputFile f;
  if (!f.open_user_path(path) || !f.write(series_text(s)) || !f.commit()) fail_series(f);
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
      // Beneath --out: never written through a symlink a pipeline's repository put there.
      SafeOutputFile f;
      if (!f.open_beneath(dir, series_file_name(n.id, s)) || !f.write(series_text(s)) || !f.commit()) fail_series(f);
      files.push_back(f.path());
    }
  return files;
}

}  // namespace trackflow::report
