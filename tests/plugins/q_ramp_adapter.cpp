// Purpose: test.q_ramp — a test-only adapter that doubles its filter's process noise at every step and publishes the value it found, to show that the engine (not the filter) restores adapted noise at the start of each run.
#include <trackflow/plugin.hpp>

namespace {

using namespace trackflow;

class QRampAdapter final : public Adapter {
 public:
  NoiseNeeds needs() const override {
    NoiseNeeds n;
    n.process = true;
    n.process_kind = NoiseKind::SpectralDensity;
    n.process_dimension = dim::accel_psd;
    n.process_axes = mask(NoiseAxes::Common) | mask(NoiseAxes::Enu);
    return n;
  }
  std::vector<std::string> annotation_names() const override { return {"q_seen"}; }

  // Deliberately no start_run: nothing here restores q, and filter.kalman does not either.
  void before_update(const Measurement&, Filter& f) override {
    const ProcessNoiseHandle q = f.noise().process;
    annotate(f, 0, q.values[0]);
    for (int i = 0; i < q.count; ++i) q.values[i] *= 2.0;
  }
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "test.q_ramp";
  d.kind = ComponentKind::Adapter;
  d.summary = "Test only: doubles the filter's q at every step and publishes the q it found (annotation q_seen)";
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = 0;
  d.create = [](const Params&) -> std::unique_ptr<Component> { return std::make_unique<QRampAdapter>(); };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("test.q_ramp", register_components)
