// Purpose: sink.mode_switch — how many steps after a known manoeuvre time a filter's annotation (e.g. an IMM's mode probability) first exceeds a threshold, and its mean before.
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace trackflow {
namespace {

struct SwitchRunResult final : RunResult {
  double steps = 0.0;      // estimates from the first one at/after `after` to the first above threshold
  bool switched = false;   // false: `steps` counts all estimates after `after` (a lower bound)
  double before_sum = 0.0; // annotation values in [after - before, after)
  std::uint64_t before_n = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.switched, r.before_sum, r.before_n);
  }
};

// Streams: each estimate is looked at once, in arrival (time) order; nothing is stored.
class ModeSwitchSink final : public Component, public FieldListCodec<SwitchRunResult> {
 public:
  ModeSwitchSink(std::string annotation, double after, double before, double threshold, SourceLoc where)
      : annotation_(std::move(annotation)), after_(after), before_(before), threshold_(threshold),
        where_(std::move(where)) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    for (const auto& in : inputs) {
      if (!(in.kinds & mask(ItemKind::Estimate))) continue;
      std::string known;
      for (size_t k = 0; k < in.annotations.size(); ++k) {
        if (in.annotations[k] == annotation_) channel_ = static_cast<int>(k);
        known += (k ? ", " : "") + in.annotations[k];
      }
      if (channel_ < 0)
        throw ConfigError("sink.mode_switch: '" + in.node + "' publishes no annotation '" + annotation_ + "' (it has: " +
                              (known.empty() ? std::string("none") : known) + ")",
                          where_);
    }
  }

  void start_run(const RunContext&) override { run_ = SwitchRunResult{}; }

  void on_estimate(const Estimate& e, int) override {
    if (!e.initialised || channel_ >= e.annotation_count) return;
    const double v = e.annotations[channel_];
    if (!std::isfinite(v)) return;
    // Times are compared with a tolerance of a microsecond (time stamps t0 + k / rate, rounded).
    if (e.time < after_ - kTolerance) {
      if (e.time >= after_ - before_ - kTolerance) {
        run_.before_sum += v;
        ++run_.before_n;
      }
      return;
    }
    if (run_.switched) return;
    if (v > threshold_)
      run_.switched = true;
    else
      run_.steps += 1.0;
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<SwitchRunResult>(run_); }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const SwitchRunResult&>(result);
    ++runs_;
    switched_ += r.switched ? 1 : 0;
    steps_sum_ += r.steps;
    steps_max_ = std::max(steps_max_, r.steps);
    before_sum_ += r.before_sum;
    before_n_ += r.before_n;
  }

  void finish(Summary& s, const FinishContext&) override {
    const double runs = static_cast<double>(runs_ ? runs_ : 1);
    s.metric("switched_fraction", static_cast<double>(switched_) / runs);
    s.metric("mean_steps", steps_sum_ / runs);
    s.metric("max_steps", steps_max_);
    if (before_n_) s.metric("mean_before", before_sum_ / static_cast<double>(before_n_));
    s.notes.push_back("steps: estimates from the first one at or after t = " + std::to_string(after_) + " s until " +
                      annotation_ + " first exceeds " + std::to_string(threshold_) +
                      " (0: at the first); a run that never does counts all its estimates after that time and lowers "
                      "switched_fraction; mean_before: its mean over the preceding " + std::to_string(before_) + " s");
  }

 private:
  static constexpr double kTolerance = 1e-6;
  std::string annotation_;
  double after_, before_, threshold_;
  SourceLoc where_;
  int channel_ = -1;
  SwitchRunResult run_;
  std::uint64_t runs_ = 0, switched_ = 0, before_n_ = 0;
  double steps_sum_ = 0.0, steps_max_ = 0.0, before_sum_ = 0.0;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.mode_switch";
  d.kind = ComponentKind::Sink;
  d.summary = "Steps after a known manoeuvre until a filter annotation (e.g. an IMM mode probability) exceeds a threshold";
  d.doc = "For each run: the number of estimates from the first one at or after `after` until the annotation "
          "(\"<filter id>.<name>\", e.g. imm.p_ca) first exceeds `threshold`; metrics switched_fraction (runs where it "
          "did), mean_steps and max_steps over the runs (a run that never switches counts all its estimates after "
          "`after`), and mean_before, the annotation's mean over [after - before, after) (so that a switch is not "
          "scored when the mode was already dominant).";
  d.accepts = mask(ItemKind::Estimate);
  d.min_inputs = 1;
  d.max_inputs = 1;
  d.params = {
      ParamSpec::string("annotation", "the annotation followed, \"<filter id>.<name>\"").req(),
      ParamSpec::real("after", dim::time, "time of the manoeuvre").req(),
      ParamSpec::real("before", dim::time, "length of the window before it for mean_before").def("1 s").positive(),
      ParamSpec::real("threshold", dim::none, "the value to exceed").def("0.5"),
  };
  d.create = [](const Params& p) -> std::unique_ptr<Component> {
    return std::make_unique<ModeSwitchSink>(p.text("annotation"), p.real("after"), p.real("before"), p.real("threshold"),
                                            p.where("annotation"));
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.mode_switch", trackflow::register_components)
