// Purpose: plugin discovery and loading with Boost.DLL, with a staged, file-naming error for each failure.
#include <trackflow/host/guard.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/names.hpp>
#include <trackflow/plugin.hpp>

#include <boost/dll/shared_library.hpp>

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace trackflow::host {
namespace {

class CollectingRegistrar : public Registrar {
 public:
  void add(ComponentDecl decl) override { decls.push_back(std::move(decl)); }
  std::vector<ComponentDecl> decls;
};

std::string size_mismatch(const PluginInfo& info) {
  const PluginInfo mine = make_plugin_info("", nullptr);
  std::string m;
  auto check = [&](const char* what, std::size_t theirs, std::size_t ours) {
    if (theirs != ours)
      m += std::string(m.empty() ? "" : ", ") + "sizeof(" + what + ") " + std::to_string(theirs) + " vs " +
           std::to_string(ours);
  };
  check("Truth", info.sizeof_truth, mine.sizeof_truth);
  check("Measurement", info.sizeof_measurement, mine.sizeof_measurement);
  check("Estimate", info.sizeof_estimate, mine.sizeof_estimate);
  check("Scan", info.sizeof_scan, mine.sizeof_scan);
  check("TrackSet", info.sizeof_track_set, mine.sizeof_track_set);
  check("InputInfo", info.sizeof_input_info, mine.sizeof_input_info);
  check("Params", info.sizeof_params, mine.sizeof_params);
  check("Component", info.sizeof_component, mine.sizeof_component);
  return m;
}

// Loaded libraries are never unloaded before the process exits (Boost.DLL FAQ): exception
// objects, type_info and static destructors from a plugin may outlive every registry and
// component, e.g. a ConfigError thrown by a factory and caught in main().
void keep_loaded(std::shared_ptr<boost::dll::shared_library> lib) {
  static auto* libraries = new std::vector<std::shared_ptr<boost::dll::shared_library>>();
  libraries->push_back(std::move(lib));
}

}  // namespace

void PluginRegistry::load_directories(const std::vector<std::string>& dirs, bool builtin) {
  for (const auto& d : dirs) {
    searched_.push_back(d);
    std::error_code ec;
    if (!fs::is_directory(d, ec)) continue;
    std::vector<fs::path> files;
    // Incremented with an error code: an unreadable entry ends the listing, it does not throw.
    for (fs::directory_iterator it(d, ec), end; !ec && it != end; it.increment(ec)) {
      const fs::path& p = it->path();
      const auto name = p.filename().string();
      if (p.extension() != ".so") continue;
      if (name.rfind("tfplugin_", 0) == 0)
        files.push_back(p);
      else
        ignored_.push_back(p.string());
    }
    std::sort(files.begin(), files.end());  // directory order is arbitrary; loading order must not be
    for (const auto& f : files) load_file(f.string(), builtin);
  }
}

void PluginRegistry::allow_replacing(std::vector<std::string> types) { replaceable_ = std::move(types); }

void PluginRegistry::load_file(const std::string& path, bool builtin) {
  std::error_code ec;
  // A looping or dangling symlink, a FIFO or a folder named tfplugin_*.so is a problem of that
  // file, not of the command (and opening a FIFO would block).
  const fs::file_status st = fs::status(path, ec);
  if (ec) {
    problems_.push_back({path, "open", "cannot resolve the file: " + ec.message()});
    return;
  }
  if (!fs::is_regular_file(st)) {
    problems_.push_back({path, "open", "not a regular file"});
    return;
  }
  for (const auto& p : plugins_) {
    std::error_code eq;
    if (fs::equivalent(p.file, path, eq) && !eq) return;
  }
  const std::string loading = path;
  Activity activity{"loading plugin", nullptr, &loading};
  ActivityScope scope(activity);  // a crash in the plugin's static constructors names the file
  auto lib = std::make_shared<boost::dll::shared_library>();
  lib->load(path, boost::dll::load_mode::rtld_lazy | boost::dll::load_mode::rtld_local, ec);
  if (ec) {
    // Boost's error text is errno's, which is misleading here; dlerror() says what went wrong.
    std::string why = ec.message();
    if (void* h = ::dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL)) {
      ::dlclose(h);
    } else if (const char* e = ::dlerror()) {
      why = e;
    }
    problems_.push_back({path, "open", why});
    return;
  }
  keep_loaded(lib);
  if (!lib->has("trackflow_plugin_v1")) {
    problems_.push_back({path, "entry", "not a trackflow plugin: no 'trackflow_plugin_v1' entry (use TRACKFLOW_PLUGIN)"});
    return;
  }
  const PluginInfo* info = lib->get_alias<const PluginInfo*()>("trackflow_plugin_v1")();
  if (!info || info->abi_version != kAbiVersion) {
    problems_.push_back({path, "abi",
                         "built against plugin ABI " + std::to_string(info ? info->abi_version : -1) + " (SDK " +
                             (info && info->sdk_version ? info->sdk_version : "?") + "); this trackflow needs ABI " +
                             std::to_string(kAbiVersion) + " (SDK " + kSdkVersion + "): rebuild the plugin"});
    return;
  }
  if (auto m = size_mismatch(*info); !m.empty()) {
    problems_.push_back({path, "abi", "SDK types differ from this trackflow's (" + m + "): rebuild the plugin"});
    return;
  }
  CollectingRegistrar reg;
  try {
    info->register_components(reg);
  } catch (const std::exception& e) {
    problems_.push_back({path, "register", std::string("registration threw: ") + e.what()});
    return;
  } catch (...) {
    problems_.push_back({path, "register", "registration threw an exception that is not a std::exception"});
    return;
  }
  LoadedPlugin loaded{path, info->plugin_name ? info->plugin_name : "", {}};
  for (auto& d : reg.decls) {
    // A type name is written in pipelines, listed and printed: "" or one with a space, a line
    // break or a control character could not be named in a pipeline and would forge output.
    if (!is_type_name(d.type)) {
      problems_.push_back({path, "register", "type name '" + quote_token(d.type) + "' refused: a type name is " +
                                                 kTypeNameRule + " (e.g. filter.kalman)"});
      continue;
    }
    const bool part = d.kind == ComponentKind::Associator || d.kind == ComponentKind::Initiator ||
                      d.kind == ComponentKind::Deleter;
    if (part ? !d.create_part : !d.create) {
      problems_.push_back({path, "register", "type '" + d.type + "' has no factory" + (part ? " (create_part)" : "")});
      continue;
    }
    if (const RegisteredType* prev = find(d.type)) {
      // A built-in type is replaced only when the user names it (--replace-type): a plugin folder
      // must not silently change what `filter.kalman` means.
      const bool asked = std::find(replaceable_.begin(), replaceable_.end(), d.type) != replaceable_.end();
      if (!prev->builtin || builtin || !asked) {
        problems_.push_back({path, "register",
                             "type '" + d.type + "' already provided by " + prev->file + " (kept that one" +
                                 (prev->builtin && !builtin ? "; it is built in: pass --replace-type " + d.type +
                                                                  " to use this plugin's instead"
                                                            : std::string()) +
                                 ")"});
        continue;
      }
      const std::string prev_file = prev->file;
      for (auto& p : plugins_)
        if (p.file == prev_file) p.types.erase(std::remove(p.types.begin(), p.types.end(), d.type), p.types.end());
      types_.erase(types_.begin() + (prev - types_.data()));
    }
    loaded.types.push_back(d.type);
    types_.push_back({lib, std::move(d), path, builtin});
  }
  plugins_.push_back(std::move(loaded));
}

const RegisteredType* PluginRegistry::find(const std::string& type) const {
  for (const auto& t : types_)
    if (t.decl.type == type) return &t;
  return nullptr;
}

std::vector<std::string> PluginRegistry::type_names() const {
  std::vector<std::string> names;
  for (const auto& t : types_) names.push_back(t.decl.type);
  std::sort(names.begin(), names.end());
  return names;
}

std::shared_ptr<Component> PluginRegistry::create(const RegisteredType& t, const Params& p) const {
  std::unique_ptr<Component> c = t.decl.create(p);
  if (!c) throw ConfigError("factory of '" + t.decl.type + "' returned nothing", p.where(), p.node());
  auto lib = t.library;
  return std::shared_ptr<Component>(c.release(), [lib](Component* ptr) { delete ptr; });
}

std::shared_ptr<Estimator> PluginRegistry::create_estimator(const RegisteredType& t, const Params& p) const {
  if (!t.decl.create_estimator) {
    std::string with;
    for (const RegisteredType& r : types())
      if (r.decl.create_estimator) with += (with.empty() ? "" : ", ") + r.decl.type;
    throw ConfigError("'" + t.decl.type + "' declares no per-track estimator; types that do: " +
                          (with.empty() ? std::string("none loaded") : with),
                      p.where(), p.node());
  }
  std::unique_ptr<Estimator> e = t.decl.create_estimator(p);
  if (!e) throw ConfigError("estimator factory of '" + t.decl.type + "' returned nothing", p.where(), p.node());
  auto lib = t.library;
  return std::shared_ptr<Estimator>(e.release(), [lib](Estimator* ptr) { delete ptr; });
}

std::vector<std::string> environment_plugin_dirs() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("TRACKFLOW_PLUGIN_PATH")) {
    std::string s = env;
    size_t pos = 0;
    while (pos <= s.size()) {
      size_t c = s.find(':', pos);
      std::string d = s.substr(pos, c == std::string::npos ? std::string::npos : c - pos);
      if (!d.empty()) dirs.push_back(d);
      if (c == std::string::npos) break;
      pos = c + 1;
    }
  }
  return dirs;
}

std::vector<std::string> builtin_plugin_dirs() {
  std::vector<std::string> dirs;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    // Build tree and installs with libdir "lib" use lib/trackflow/plugins; Debian-style
    // multiarch installs use the configured CMAKE_INSTALL_LIBDIR.
    const fs::path prefix = exe.parent_path().parent_path();
    dirs.push_back((prefix / "lib" / "trackflow" / "plugins").lexically_normal().string());
    const fs::path installed = (prefix / TRACKFLOW_INSTALL_PLUGIN_RELDIR).lexically_normal();
    if (installed.string() != dirs.back()) dirs.push_back(installed.string());
  }
  return dirs;
}

std::vector<std::string> default_plugin_dirs() {
  std::vector<std::string> dirs = environment_plugin_dirs();
  for (auto& d : builtin_plugin_dirs()) dirs.push_back(std::move(d));
  return dirs;
}

}  // namespace trackflow::host
