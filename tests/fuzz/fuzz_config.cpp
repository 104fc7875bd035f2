// Purpose: libFuzzer harness of the YAML pipeline loader with units: any bytes as a pipeline file must end in a pipeline or a ConfigError -- no crash, hang, other exception or sanitizer report.
#include "fuzz_common.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace trackflow;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const host::Value root = host::load_yaml_string(text, "fuzz.yaml");
    const host::PipelineConfig cfg = host::parse_pipeline(root, "fuzz.yaml");
    fuzz::validate_all(cfg);
  } catch (const ConfigError& e) {
    (void)e.message();  // the message itself must be buildable
  }
  return 0;
}
