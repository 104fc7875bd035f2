// Purpose: a plugin as an older SDK built it (ABI 3 to 8, chosen by OLD_ABI): its entry point with that SDK's PluginInfo layout, which the loader must refuse by its ABI number before reading any other field.
#include <boost/dll/alias.hpp>

#include <cstddef>

#ifndef OLD_ABI
#error "define OLD_ABI (3 to 8)"
#endif

namespace {

struct Registrar;
// PluginInfo of SDK 0.3 and 0.4: the ABI number and SDK version first (as in every SDK), then
// five type sizes and the registration function. SDK 0.5 to 0.8 had more sizes, but a loader must stop
// reading at the ABI number, so the shorter layout stands for it too.
struct OldPluginInfo {
  int abi_version;
  const char* sdk_version;
  const char* plugin_name;
  std::size_t sizeof_truth, sizeof_measurement, sizeof_estimate, sizeof_params, sizeof_component;
  void (*register_components)(Registrar&);
};

// Never called: a loader that ran it would have accepted an old plugin.
void register_nothing(Registrar&) { __builtin_trap(); }

const OldPluginInfo* entry() {
  static const OldPluginInfo info{OLD_ABI, OLD_ABI == 3 ? "0.3.0" : OLD_ABI == 4 ? "0.4.1" : OLD_ABI == 5 ? "0.5.0" : OLD_ABI == 6 ? "0.6.0" : OLD_ABI == 7 ? "0.7.0" : "0.8.0", "old", 8, 400, 3000, 64, 16,
                                  register_nothing};
  return &info;
}

}  // namespace

BOOST_DLL_ALIAS(entry, trackflow_plugin_v1)
