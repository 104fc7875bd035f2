// Purpose: the rule of output_path.hpp: sinks' relative file names stay under --out unless the command line allows more.
#include <trackflow/output_path.hpp>

#include <atomic>
#include <filesystem>

namespace trackflow {
namespace {
std::atomic<bool> g_outside_allowed{false};
// Per thread: build_graph instantiates on the calling thread, while worker threads constructing
// their own copies of the graph declare into nothing.
thread_local std::vector<DeclaredOutput>* t_declared = nullptr;
}  // namespace

void declare_output_file(const std::string& node, const std::string& relative_path) {
  if (t_declared) t_declared->push_back({node, relative_path});
}

void collect_declared_outputs(std::vector<DeclaredOutput>* into) { t_declared = into; }

std::string output_path_problem(const std::string& path) {
  if (g_outside_allowed.load()) return {};
  const std::filesystem::path p(path);
  if (p.has_root_path()) return "'" + path + "' is an absolute path; sinks write under --out";
  int depth = 0;
  for (const auto& part : p.lexically_normal()) {
    const std::string s = part.string();
    if (s == "..") --depth;
    else if (!s.empty() && s != ".") ++depth;
    if (depth < 0) return "'" + path + "' leaves the output folder ('..'); sinks write under --out";
  }
  return {};
}

void allow_output_outside(bool allowed) { g_outside_allowed = allowed; }
bool output_outside_allowed() { return g_outside_allowed.load(); }

}  // namespace trackflow
