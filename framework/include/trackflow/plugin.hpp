// Purpose: the single entry point a plugin .so exports (TRACKFLOW_PLUGIN), with the ABI handshake.
#pragma once

#include <trackflow/params.hpp>
#include <trackflow/registry.hpp>
#include <trackflow/version.hpp>

#include <boost/dll/alias.hpp>

#include <cstddef>

namespace trackflow {

// Exported by every plugin; the loader compares each field with its own before calling
// register_components, so a plugin built against another SDK is refused, not run. abi_version
// comes first and stays first: an older plugin's info is read no further than it.
struct PluginInfo {
  int abi_version;
  const char* sdk_version;
  const char* plugin_name;
  std::size_t sizeof_truth;
  std::size_t sizeof_measurement;
  std::size_t sizeof_estimate;
  std::size_t sizeof_scan;
  std::size_t sizeof_track_set;
  std::size_t sizeof_input_info;
  std::size_t sizeof_params;
  std::size_t sizeof_component;
  void (*register_components)(Registrar&);
};

inline PluginInfo make_plugin_info(const char* name, void (*fn)(Registrar&)) {
  return {kAbiVersion, kSdkVersion, name, sizeof(Truth), sizeof(Measurement), sizeof(Estimate),
          sizeof(Scan), sizeof(TrackSet), sizeof(InputInfo), sizeof(Params), sizeof(Component), fn};
}

}  // namespace trackflow

// Use once per plugin: TRACKFLOW_PLUGIN("kalman", register_fn) where
// `void register_fn(trackflow::Registrar&)` adds the plugin's component types.
#define TRACKFLOW_PLUGIN(NAME, REGISTER_FN)                                       \
  namespace {                                                                      \
  const ::trackflow::PluginInfo* trackflow_plugin_entry() {                        \
    static const ::trackflow::PluginInfo info = ::trackflow::make_plugin_info(NAME, REGISTER_FN); \
    return &info;                                                                  \
  }                                                                                \
  }                                                                                \
  BOOST_DLL_ALIAS(trackflow_plugin_entry, trackflow_plugin_v1)
