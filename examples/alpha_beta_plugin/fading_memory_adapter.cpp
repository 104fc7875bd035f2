// Purpose: adapt.fading_memory — example third-party adapter: fading-memory Kalman filtering by rescaling the attached filter's state covariance before every update.
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <cmath>
#include <memory>

namespace {

using namespace trackflow;

// The adapter's per-run result. Its one field list is its codec under mpirun (FieldListCodec):
// the processes of the job each run some runs and send these to the first, which merges them.
struct ScaleCount final : RunResult {
  std::uint64_t scales = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.scales);
  }
};

// Fading memory (Sorenson & Sacks 1971; Bar-Shalom, Li & Kirubarajan 2001, §5.2.4 and §11.7):
// P⁻ = α² F P Fᵀ + Q with α ≥ 1 weights old data less, which keeps a filter responsive to
// unmodelled manoeuvres. Multiplying P by α² before the filter predicts and updates with a
// measurement is the same thing up to where Q is added (α² scales P, then F P Fᵀ + Q): done here
// through the SDK's covariance handle (Filter::scale_covariance), so it works with any filter
// that has one, whatever its state or how it stores P.
class FadingMemoryAdapter final : public Adapter, public FieldListCodec<ScaleCount> {
 public:
  explicit FadingMemoryAdapter(double alpha) : factor_(alpha * alpha) {}

  // Touches only the state covariance: refused (at validate time) by a filter without the handle.
  NoiseNeeds needs() const override {
    NoiseNeeds n;
    n.covariance = true;
    return n;
  }

  std::vector<std::string> annotation_names() const override { return {"scaled_variance"}; }

  void start_run(const RunContext&) override { scales_ = 0; }

  void before_update(const Measurement& m, Filter& f) override {
    if (!m.valid) return;  // coasting: nothing new to weigh against
    f.scale_covariance(factor_);
    ++scales_;
    // Position variance after the rescale, published on every estimate (e.g. a sink.csv column).
    StateCov P;
    f.read_covariance(P);
    if (P.rows() > 0) annotate(f, 0, P(0, 0));
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<ScaleCount>();
    r->scales = scales_;
    return r;
  }
  void merge(RunResult& r) override { total_ += static_cast<ScaleCount&>(r).scales; }
  void finish(Summary& s, const FinishContext&) override {
    s.metric("covariance_rescales", static_cast<double>(total_));
    s.metric("variance_factor", factor_);
  }

 private:
  double factor_;
  std::uint64_t scales_ = 0, total_ = 0;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "adapt.fading_memory";
  d.kind = ComponentKind::Adapter;
  d.summary = "Fading-memory filtering: the attached filter's state covariance times alpha^2 before every update "
              "(example third-party adapter)";
  d.doc =
      "Sorenson & Sacks 1971: P <- alpha^2 P before each valid measurement is used (alpha >= 1; 1 changes nothing), "
      "through the SDK's covariance handle, so it attaches to any filter that exposes one. Publishes the rescaled "
      "first state variance as the annotation scaled_variance.";
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = 0;
  d.params = {ParamSpec::real("alpha", dim::none, "fading factor alpha >= 1 (P is multiplied by alpha^2)")
                  .def("1.02")
                  .at_least(1)
                  .at_most(10)};
  d.create = [](const Params& p) -> std::unique_ptr<Component> {
    return std::make_unique<FadingMemoryAdapter>(p.real("alpha"));
  };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("adapt.fading_memory", register_components)
