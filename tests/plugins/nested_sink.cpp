// Purpose: test.nested — a test-only sink declaring one Component and one ComponentList parameter of filter types, to check that nested components are validated against their own types' declarations.
#include <trackflow/plugin.hpp>

#include <stdexcept>

namespace {

using namespace trackflow;

class Nested final : public Component {
 public:
  // Reads the nested values at create time, as a plugin that builds its sub-filters would.
  explicit Nested(const Params& p) : primary_(p.component("primary").type) {
    for (const auto& m : p.components("modes")) modes_.push_back(m.type);
  }
  void on_estimate(const Estimate&, int) override {}

 private:
  std::string primary_;
  std::vector<std::string> modes_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.nested";
  d.kind = ComponentKind::Sink;
  d.summary = "Test only: takes one nested filter (primary) and a list of them (modes)";
  d.accepts = mask(ItemKind::Estimate);
  d.produces = 0;
  d.params = {ParamSpec::component("primary", {ComponentKind::Filter}, "one filter").req(),
              ParamSpec::component_list("modes", {ComponentKind::Filter}, "filters whose type starts with filter.")
                  .with_prefix("filter.")
                  .def("[]")};
  d.create = [](const Params& p) -> std::unique_ptr<Component> { return std::make_unique<Nested>(p); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.nested", register_components)
