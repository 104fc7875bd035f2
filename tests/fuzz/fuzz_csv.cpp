// Purpose: libFuzzer harness of the CSV reader: any bytes as a source.csv log (with a few parameter variants chosen by the first byte) must replay as measurements or end in a DataError/ConfigError, and every replayed measurement is finite.
#include <trackflow/host/config.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/plugin.hpp>

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

// The plugin's entry point, compiled into this harness (plugins/source/csv/csv_source.cpp).
namespace _autoaliases {
extern "C" const void* trackflow_plugin_v1;
}

namespace {

using namespace trackflow;

class Keep : public Registrar {
 public:
  void add(ComponentDecl d) override {
    if (d.type == "source.csv") decl = std::move(d);
  }
  ComponentDecl decl;
};

// Counts what the source emits and checks each measurement on the way.
class Sink : public Component {
 public:
  void on_measurement(const Measurement& m, int) override {
    if (!std::isfinite(m.time) || !m.value.allFinite()) std::abort();  // a NaN escaped the reader
    ++count;
  }
  std::size_t count = 0;
};

const ComponentDecl& decl() {
  static const ComponentDecl d = [] {
    auto entry = reinterpret_cast<const PluginInfo* (*)()>(reinterpret_cast<std::intptr_t>(_autoaliases::trackflow_plugin_v1));
    Keep k;
    entry()->register_components(k);
    return k.decl;
  }();
  return d;
}

const char* kVariants[] = {
    "",
    ", on_bad_row: skip",
    ", frame: cartesian, position_unit: km",
    ", range_rate_column: rr, snr_column: snr, mode_column: mode, valid_column: ok, sensor_column: id, on_bad_row: skip",
    ", time_unit: ms, range_unit: km, angle_unit: rad",
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static int n = 0;
  const std::string path = "/tmp/tf_fuzz_csv_" + std::to_string(::getpid()) + "_" + std::to_string(n++ % 64) + ".csv";
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
  }
  const std::string yaml = "{path: " + path + std::string(kVariants[data[0] % 5]) + "}";
  try {
    const host::Value v = host::load_yaml_string(yaml, "fuzz.yaml");
    const Params p = host::validate_params(decl().params, v, "log", v.loc);
    std::unique_ptr<Component> c = decl().create(p);
    auto& gen = dynamic_cast<Generator&>(*c);
    Sink sink;
    Link link{&sink, 0, 0xFF};
    c->out.connect(&link, 1);
    Diagnostics diag;
    for (std::uint64_t run = 0; run < 2; ++run) {
      c->start_run({run, 1, &diag});
      double last = -INFINITY;
      for (int guard = 0; std::isfinite(gen.next_time()); ++guard) {
        if (gen.next_time() < last || guard > 10'000'000) std::abort();  // time order, and an end
        last = gen.next_time();
        gen.emit_next();
      }
    }
    Summary s;
    c->finish(s, {"log", "", 2});
  } catch (const DataError&) {
  } catch (const ConfigError&) {
  }
  std::remove(path.c_str());
  return 0;
}
