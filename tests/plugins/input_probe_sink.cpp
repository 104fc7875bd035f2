// Purpose: test.input_probe — a test-only sink that reports, as summary notes, what the host told it about each input (InputInfo: kinds, time order, the upstream filter's state layout), so the CLI tests can check what reaches set_inputs.
#include <trackflow/plugin.hpp>

#include <string>
#include <vector>

namespace {

using namespace trackflow;

class InputProbe final : public Component {
 public:
  void set_inputs(const std::vector<InputInfo>& inputs) override {
    notes_.clear();
    for (const InputInfo& in : inputs) {
      std::string n = "input " + in.node + ": time_ordered=" + (in.time_ordered ? "yes" : "no") + ", state=[";
      for (int i = 0; i < in.state.dim; ++i)
        n += std::string(i ? " " : "") + in.state.components[i].name + "(" + in.state.components[i].unit + ")";
      notes_.push_back(n + "]");
    }
  }
  void on_truth(const Truth&, int) override {}
  void on_measurement(const Measurement&, int) override {}
  void on_estimate(const Estimate&, int) override {}
  void finish(Summary& s, const FinishContext&) override {
    for (const std::string& n : notes_) s.notes.push_back(n);
  }

 private:
  std::vector<std::string> notes_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.input_probe";
  d.kind = ComponentKind::Sink;
  d.summary = "Test only: reports each input's InputInfo (time order, state layout) as summary notes";
  d.accepts = ItemKind::Truth | ItemKind::Measurement | mask(ItemKind::Estimate);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.create = [](const Params&) { return std::make_unique<InputProbe>(); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.input_probe", register_components)
