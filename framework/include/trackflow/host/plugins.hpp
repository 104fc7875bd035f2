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
  bool builtin = false;  // from the installed (or build-tree) plugin folder
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
  // files declare the same type, the first one found wins and the other is a LoadProblem --
  // except that a type of a `builtin` folder loaded earlier is replaced by a later plugin when
  // it was named in allow_replacing (the CLI's --replace-type).
  void load_directories(const std::vector<std::string>& dirs, bool builtin = false);
  // Loads one file; problems are recorded, not thrown.
  void load_file(const std::string& path, bool builtin = false);
  void allow_replacing(std::vector<std::string> types);

  const RegisteredType* find(const std::string& type) const;
  std::vector<std::string> type_names() const;
  const std::vector<RegisteredType>& types() const { return types_; }
  const std::vector<LoadedPlugin>& plugins() const { return plugins_; }
  const std::vector<LoadProblem>& problems() const { return problems_; }
  const std::vector<std::string>& searched() const { return searched_; }
  // Shared objects in the searched folders not named tfplugin_*.so (not loaded: a plugin's own
  // libraries may sit beside it, but a misnamed plugin is told when its type is not found).
  const std::vector<std::string>& ignored() const { return ignored_; }

  // The component lives as long as the returned pointer; its deleter keeps the library loaded.
  std::shared_ptr<Component> create(const RegisteredType& t, const Params& p) const;
  // The per-track estimator of a filter type that declares one (ComponentDecl::create_estimator);
  // it keeps its plugin loaded. A type without one is refused, naming the types that have one.
  std::shared_ptr<Estimator> create_estimator(const RegisteredType& t, const Params& p) const;

 private:
  std::vector<RegisteredType> types_;
  std::vector<LoadedPlugin> plugins_;
  std::vector<LoadProblem> problems_;
  std::vector<std::string> searched_;
  std::vector<std::string> ignored_;
  std::vector<std::string> replaceable_;
};

// The installed (or build-tree) plugin folder: <executable dir>/../lib/trackflow/plugins and
// <prefix>/<libdir>/trackflow/plugins. Its types are the built-in ones.
std::vector<std::string> builtin_plugin_dirs();
// $TRACKFLOW_PLUGIN_PATH, colon-separated.
std::vector<std::string> environment_plugin_dirs();
// $TRACKFLOW_PLUGIN_PATH, then the built-in folders (for tools that take everything).
std::vector<std::string> default_plugin_dirs();

}  // namespace trackflow::host
