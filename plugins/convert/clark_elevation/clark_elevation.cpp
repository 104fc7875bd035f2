// Purpose: convert.clark_elevation — the baseline of paper 004: Clark's refraction bias taken out of each measured elevation directly (paper 004 ref [3]), spherical in, spherical out.
#include "physics/refraction.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

namespace trackflow {
namespace {

// Where Clark's b is evaluated: at the measured (apparent) elevation, as paper 004's baseline
// does, or at the elevation that the correction returns (theta + b(theta) = theta_m, solved by
// fixed-point iteration, which converges because |b'| < 0.3 above 2 deg).
enum class EvaluateAt { Measured, Solved };

struct ClarkRunResult final : RunResult {
  std::uint64_t corrected = 0, invalid = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.corrected, r.invalid);
  }
};

// theta_c = theta_m - b(theta_e); range, azimuth and range rate pass unchanged. The elevation
// variance and its covariances are mapped by d theta_c / d theta_m (1 - b'(theta_m) at the
// measured point, 1 / (1 + b'(theta_c)) when solved). Below 2 deg clark_below_2deg decides:
// invalid passes the measurement on with valid = false (counted; filters coast), hold uses b(2 deg),
// extrapolate the 2-10 deg formula. Invalid measurements pass through untouched.
class ClarkElevation final : public Component, public FieldListCodec<ClarkRunResult> {
 public:
  ClarkElevation(sim::ClarkModel model, EvaluateAt at, int iterations)
      : model_(model), at_(at), iterations_(iterations) {}

  void start_run(const RunContext&) override { run_ = ClarkRunResult{}; }

  void on_measurement(const Measurement& in, int) override {
    if (!in.valid || in.frame != Frame::Spherical) {
      out.emit(in);
      return;
    }
    m_ = in;
    const double z = in.value(2);
    if (!model_.defined(z)) {
      m_.valid = false;
      ++run_.invalid;
      out.emit(m_);
      return;
    }
    double theta = z - model_.bias(z), gain = 1.0 - model_.at(z).db;
    if (at_ == EvaluateAt::Solved) {
      for (int k = 0; k < iterations_; ++k) theta = z - model_.bias(theta);
      gain = 1.0 / (1.0 + model_.at(theta).db);
    }
    m_.value(2) = theta;
    const int n = static_cast<int>(m_.value.size());
    for (int j = 0; j < n; ++j) {
      m_.covariance(2, j) *= gain;
      m_.covariance(j, 2) *= gain;
    }
    ++run_.corrected;
    out.emit(m_);
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<ClarkRunResult>(run_); }
  void merge(RunResult& r) override {
    const auto& c = static_cast<ClarkRunResult&>(r);
    total_.corrected += c.corrected;
    total_.invalid += c.invalid;
  }
  void finish(Summary& s, const FinishContext&) override {
    s.metric("corrected", static_cast<double>(total_.corrected));
    s.metric("invalid_below_2deg", static_cast<double>(total_.invalid));
    if (total_.invalid)
      s.notes.push_back(std::to_string(total_.invalid) +
                        " measurement(s) below 2 deg passed on invalid (Clark is undefined there; clark_below_2deg)");
  }

 private:
  sim::ClarkModel model_;
  EvaluateAt at_;
  int iterations_;
  Measurement m_;
  ClarkRunResult run_, total_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "convert.clark_elevation";
  d.kind = ComponentKind::Converter;
  d.summary = "Paper 004's baseline: measured elevation corrected directly by Clark's refraction bias (spherical in "
              "and out)";
  d.doc = "theta_c = theta_m - b(theta_e), b Clark's model (n0, clark_coefficients, clark_theta_unit; see sim.radar). "
          "evaluate_at: measured takes theta_e = theta_m, the measured (biased, noisy) elevation, as paper 004's "
          "reference [3] does; solved iterates theta_e = theta_m - b(theta_e) (iterations times), i.e. evaluates b at "
          "the corrected elevation, as the radar's model b(theta) of the true elevation requires. The elevation's "
          "variance and covariances are scaled by d theta_c / d theta_m. Below 2 deg: clark_below_2deg (invalid: the "
          "measurement is passed on invalid and counted). Range, azimuth, range rate and invalid measurements pass "
          "unchanged. Feed an ordinary filter (filter.ekf, filter.ukf, ...) or score it directly.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Measurement);
  d.accepts_frames = mask(Frame::Spherical);
  d.produces_frames = mask(Frame::Spherical);
  d.params = {sim::n0_param()};
  for (auto& spec : sim::clark_param_specs(true)) d.params.push_back(std::move(spec));
  d.params.push_back(ParamSpec::choice<EvaluateAt>("evaluate_at",
                                                   {{EvaluateAt::Measured, "measured"}, {EvaluateAt::Solved, "solved"}},
                                                   "evaluate b at the measured elevation (paper 004's baseline) or at the "
                                                   "corrected one (fixed point)")
                         .def("measured"));
  d.params.push_back(
      ParamSpec::integer("iterations", "evaluate_at: solved: fixed-point iterations").def("8").at_least(1).at_most(100));
  d.create = [](const Params& p) {
    const auto at = p.choice<EvaluateAt>("evaluate_at");
    if (at != EvaluateAt::Solved && p.given("iterations")) throw p.error("iterations", "is for evaluate_at: solved");
    return std::make_unique<ClarkElevation>(sim::read_clark(p, true), at, static_cast<int>(p.integer("iterations")));
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("convert.clark_elevation", trackflow::register_components)
