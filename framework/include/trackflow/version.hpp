// Purpose: SDK and plugin ABI version numbers checked when a plugin is loaded.
#pragma once

namespace trackflow {

// Bump kAbiVersion whenever a type that crosses the plugin boundary changes layout or
// a virtual function is added, removed or reordered. The loader refuses mismatches.
inline constexpr int kAbiVersion = 4;  // 4: Measurement::sensor_axes, sensor_level; a filter's own annotations (issue 14)
inline constexpr const char* kSdkVersion = "0.4.1";  // 0.4.1: FieldListCodec, put_all / get_all (header only)

}  // namespace trackflow
