// Purpose: finds plugin .so files, checks their ABI handshake, and creates components from them.
#pragma once

#include <trackflow/registry.hpp>

#include <memory>
#include <string>
#include <vector>

namespace boost::dll {
class shared_library;
}

namespace trackflow::host {

struct RegisteredType {
  // Declared first so it is destroyed last: decl holds a std::function whose code lives in
  // the library.
  std::shared_ptr<boost::dll::shared_library> library;
  ComponentDecl decl;
  std::string file;  // the .so it came from
};

struct LoadedPlugin {
  std::string file;
  std::string name;
  std::vector<std::string> types;
};

// A plugin file that could not be used, and at which stage: "open" (dlopen failed),
// "entry" (not a trackflow plugin), "abi" (built against another SDK), "register" (threw).
struct LoadProblem {
  std::string file;
  std::string stage;
  std::string message;
  std::string str() const { return file + ": " + stage + ": " + message; }
};

class PluginRegistry {
 public:
  // Loads every file named tfplugin_*.so in each directory, in the order given. When two
  // files declare the same type, the first one found wins and the other is a LoadProblem.
  void load_directories(const std::vector<std::string>& dirs);
  // Loads one file; problems are recorded, not thrown.
  void load_file(const std::string& path);

  const RegisteredType* find(const std::string& type) const;
  std::vector<std::string> type_names() const;
  const std::vector<RegisteredType>& types() const { return types_; }
  const std::vector<LoadedPlugin>& plugins() const { return plugins_; }
  const std::vector<LoadProblem>& problems() const { return problems_; }
  const std::vector<std::string>& searched() const { return searched_; }

  // The component lives as long as the returned pointer; its deleter keeps the library loaded.
  std::shared_ptr<Component> create(const RegisteredType& t, const Params& p) const;

 private:
  std::vector<RegisteredType> types_;
  std::vector<LoadedPlugin> plugins_;
  std::vector<LoadProblem> problems_;
  std::vector<std::string> searched_;
};

// Default search path after --plugin-path and the pipeline's plugin_paths:
// $TRACKFLOW_PLUGIN_PATH (colon-separated), then <executable dir>/../lib/trackflow/plugins.
std::vector<std::string> default_plugin_dirs();

}  // namespace trackflow::host
