// Purpose: the list of data files components named (data_files.hpp), kept for the MPI ranks' comparison.
#include <trackflow/data_files.hpp>

#include <algorithm>
#include <mutex>

namespace trackflow {
namespace {

struct Noted {
  std::mutex mutex;
  std::vector<std::string> paths;
};
Noted& noted() {
  static Noted n;
  return n;
}

}  // namespace

void note_data_file(const std::string& path) {
  Noted& n = noted();
  std::lock_guard<std::mutex> lock(n.mutex);
  if (std::find(n.paths.begin(), n.paths.end(), path) == n.paths.end()) n.paths.push_back(path);
}

namespace detail {
std::vector<std::string> noted_data_files() {
  Noted& n = noted();
  std::lock_guard<std::mutex> lock(n.mutex);
  return n.paths;
}
}  // namespace detail

}  // namespace trackflow
