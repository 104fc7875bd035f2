// Purpose: test-only plugin that registers type names no pipeline could name ("", one with a space, one with a line break and a terminal escape) beside a good one, for tests/hostile.
#include <trackflow/plugin.hpp>

namespace {

using namespace trackflow;

class Pass final : public Component {
 public:
  void on_measurement(const Measurement& m, int) override { out.emit(m); }
};

void add(Registrar& r, const char* type) {
  ComponentDecl d;
  d.type = type;
  d.kind = ComponentKind::Converter;
  d.summary = "Test only: passes measurements on";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.create = [](const Params&) -> std::unique_ptr<Component> { return std::make_unique<Pass>(); };
  r.add(d);
}

void register_components(Registrar& r) {
  add(r, "");
  add(r, "test.bad name");
  add(r, "test.forged\ntrackflow: all good\x1b[2J");
  add(r, "test.good_name");
}

}  // namespace

TRACKFLOW_PLUGIN("test.bad_type_names", register_components)
