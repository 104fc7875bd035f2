// Purpose: the rule of output_path.hpp: sinks' relative file names stay under --out unless the command line allows more.
#include <trackflow/output_path.hpp>

#include <atomic>
#include <filesystem>

namespace trackflow {
namespace {
std::atomic<bool> g_outside_allowed{false};
}

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
