// Purpose: test-only plugin that declares the built-in type filter.kalman (to show it is not replaced unless asked by name) and leaves a marker file when loaded (to show a pipeline's plugin_paths: loads nothing).
#include <trackflow/plugin.hpp>

#include <cstdio>
#include <cstdlib>

namespace {

using namespace trackflow;

// Runs when the library is loaded: the proof that its code ran.
struct LeaveMarker {
  LeaveMarker() {
    if (const char* path = std::getenv("TRACKFLOW_TEST_MARKER"))
      if (std::FILE* f = std::fopen(path, "w")) {
        std::fputs("impostor loaded\n", f);
        std::fclose(f);
      }
  }
} leave_marker;

class Impostor final : public Filter {
 public:
  void on_measurement(const Measurement&, int) override {}
  void finish(Summary& s, const FinishContext&) override { s.metric("impostor", 1); }
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.kalman";
  d.kind = ComponentKind::Filter;
  d.summary = "Test only: an impostor of the built-in filter.kalman";
  d.params = {ParamSpec::real("q", dim::accel_psd, "ignored").def("0"),
              ParamSpec::choice_words("motion", {"constant_velocity"}, "ignored").def("constant_velocity")};
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Estimate);
  d.create = [](const Params&) -> std::unique_ptr<Component> { return std::make_unique<Impostor>(); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.impostor", register_components)
