// Purpose: libFuzzer harness of the --set and sweep --param parsers: any text as `--set` or `--param` must apply to a pipeline or end in a ConfigError.
#include "fuzz_common.hpp"

#include <trackflow/host/sweep.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

namespace {

const char* kBase = R"(pipeline: {name: fuzz, seed: 1, runs: 1}
nodes:
  - {id: a, type: x, params: {length: 5 m, rate: 10 Hz}}
  - {id: b, type: y, input: a}
expect:
  a.m: {max: 1}
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace trackflow;
  const std::string text(reinterpret_cast<const char*>(data), size);
  static const host::Value root = host::load_yaml_string(kBase, "base.yaml");
  try {
    const host::Override o = host::parse_override(text);
    const host::PipelineConfig cfg = host::parse_pipeline(root, "base.yaml", {o});
    fuzz::validate_all(cfg);
  } catch (const ConfigError& e) {
    (void)e.message();
  }
  try {
    const host::SweepAxis axis = host::parse_sweep_axis(text);
    const auto grid = host::sweep_grid({axis, axis});
    for (std::size_t i = 0; i < grid.size() && i < 4; ++i) {
      try {
        fuzz::validate_all(host::parse_pipeline(root, "base.yaml", grid[i]));
      } catch (const ConfigError&) {
      }
    }
  } catch (const ConfigError& e) {
    (void)e.message();
  }
  return 0;
}
