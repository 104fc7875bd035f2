// Purpose: adapt.range_r — paper 003's adaptive EKF: the angle part of a spherical R set from the measured range, R(r) = alpha (r/r0)^a + beta (r0/r)^b (Fig 29).
#include "range_law.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace trackflow {
namespace {

using adapt::RangeLaw;

struct RangeRRunResult final : RunResult {
  double sum = 0.0, thermal_sum = 0.0;  // of R and its thermal part over the adapted updates, rad^2
  double min = std::numeric_limits<double>::infinity(), max = 0.0;
  std::uint64_t adapted = 0, skipped = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.sum, r.thermal_sum, r.min, r.max, r.adapted, r.skipped);
  }
};

// Written before each update into the filter's R (a spherical [range, azimuth, elevation(, range rate)]
// R): the azimuth and elevation variances become R(r) at the measured range (paper 003 assumes range is
// tracked perfectly, so the measurement's range is the range), their correlations with the other
// channels are removed; range and range-rate entries stay the measurement's own.
class RangeRAdapter final : public Adapter, public FieldListCodec<RangeRRunResult> {
 public:
  explicit RangeRAdapter(RangeLaw law) : law_(law) {}

  NoiseNeeds needs() const override {
    NoiseNeeds n;
    n.measurement = MeasurementSpace::Spherical;
    return n;
  }

  std::vector<std::string> annotation_names() const override { return {"sigma_angle"}; }

  void start_run(const RunContext&) override { run_ = RangeRRunResult{}; }

  void before_update(const Measurement& m, Filter& f) override {
    MeasCov* R = f.noise().measurement.R;
    if (!R || !m.valid || m.value.size() < 3 || R->rows() < 3) return;
    const double r = m.value(0);
    if (!std::isfinite(r) || !(r > 0.0)) {
      ++run_.skipped;  // no usable range: the filter keeps the measurement's own R
      return;
    }
    const double v = law_.variance(r);
    for (int i = 1; i <= 2; ++i) {
      R->row(i).setZero();
      R->col(i).setZero();
      (*R)(i, i) = v;
    }
    annotate(f, 0, std::sqrt(v));
    ++run_.adapted;
    run_.sum += v;
    run_.thermal_sum += law_.thermal(r);
    run_.min = std::min(run_.min, v);
    run_.max = std::max(run_.max, v);
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<RangeRRunResult>(run_); }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const RangeRRunResult&>(result);
    total_.sum += r.sum;
    total_.thermal_sum += r.thermal_sum;
    total_.adapted += r.adapted;
    total_.skipped += r.skipped;
    total_.min = std::min(total_.min, r.min);
    total_.max = std::max(total_.max, r.max);
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("updates", static_cast<double>(total_.adapted));
    if (total_.skipped) s.metric("skipped", static_cast<double>(total_.skipped));
    if (total_.adapted == 0) {
      s.notes.push_back("no valid measurement reached the adapter: R was never set");
      return;
    }
    const double n = static_cast<double>(total_.adapted);
    s.metric("sigma_of_mean_r", std::sqrt(total_.sum / n), "rad");
    s.metric("sigma_min", std::sqrt(total_.min), "rad");
    s.metric("sigma_max", std::sqrt(total_.max), "rad");
    s.metric("thermal_fraction", total_.thermal_sum / total_.sum);
    if (law_.alpha > 0.0 && law_.beta > 0.0 && law_.thermal_exponent > 0.0 && law_.glint_exponent > 0.0)
      s.metric("minimum_range", law_.minimum_range(), "m");
    s.notes.push_back("sigma_of_mean_r = sqrt of the mean R(r) over every adapted update of every run: the fixed R "
                      "paper 003 gives its EKF; thermal_fraction = the thermal part's share of that mean; "
                      "minimum_range = where R(r) is smallest");
  }

 private:
  RangeLaw law_;
  RangeRRunResult run_, total_;
};

const char* const kDoc =
    "Paper 003 (Song 2017) Fig 29: the adaptive EKF's measurement noise varies with range, R(r) = R_t + R_g with a "
    "thermal part R_t = alpha (r / reference_range)^thermal_exponent (the radar equation: SNR ~ r^-4, angle "
    "variance ~ 1/SNR) and a glint part R_g = beta (reference_range / r)^glint_exponent (angular glint = linear glint "
    "/ r, eq 3-11); alpha and beta are their variances at reference_range (the paper draws R_t and R_g with 'base "
    "covariances' alpha and beta but prints no formula; this is the reading the two noise laws give). Before each "
    "update of a valid measurement, the azimuth and elevation variances of the filter's spherical R are set to R(r) "
    "at the measured range r (range is assumed perfectly tracked, as in the paper), their correlations removed; the "
    "range (and range-rate) variance stays the measurement's own. Ranges below min_range are evaluated at min_range. "
    "Needs a filter whose R is in spherical measurement space (filter.ekf, filter.ukf, filter.ekf_spherical, "
    "filter.gain_transform); `validate` refuses it on a Cartesian filter. Publishes sigma_angle = sqrt(R(r)) on "
    "every estimate; reports sigma_of_mean_r (the square root of the mean R over all adapted updates: paper 003's "
    "fixed-R EKF uses the adaptive filter's mean R), sigma_min, sigma_max, thermal_fraction and minimum_range "
    "(where R(r) is smallest). Setting both exponents to 0 makes R constant, alpha + beta: the adapter then acts as "
    "a fixed R. docs/filters.md.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "adapt.range_r";
  d.kind = ComponentKind::Adapter;
  // Its channels are three position values (2-D measurements are refused when the pipeline is built).
  d.accepts_frames = mask(Frame::Spherical);
  d.summary = "Range-dependent angle noise R(r) = thermal part (grows with range) + glint part (shrinks), paper 003";
  d.doc = kDoc;
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = 0;
  const Dimension angle2{0, 0, 2, 0};  // rad^2
  d.params = {
      ParamSpec::real("alpha", angle2, "thermal angle variance at reference_range, e.g. 400 urad2").req().at_least(0),
      ParamSpec::real("beta", angle2, "glint angle variance at reference_range, e.g. 900 urad2").req().at_least(0),
      ParamSpec::real("reference_range", dim::length, "range r0 at which alpha and beta hold").req().positive(),
      ParamSpec::real("thermal_exponent", dim::none, "a in (r/r0)^a of the thermal part (radar equation: 4)")
          .def("4")
          .at_least(0)
          .at_most(10),
      ParamSpec::real("glint_exponent", dim::none, "b in (r0/r)^b of the glint part (glint over range: 2)")
          .def("2")
          .at_least(0)
          .at_most(10),
      ParamSpec::real("min_range", dim::length, "ranges below this are evaluated here").def("1 m").positive(),
  };
  d.create = [](const Params& p) {
    RangeLaw law;
    law.alpha = p.real("alpha");
    law.beta = p.real("beta");
    if (law.alpha + law.beta <= 0.0) throw p.error("beta", "alpha and beta are both 0: R would be 0");
    law.reference_range = p.real("reference_range");
    law.thermal_exponent = p.real("thermal_exponent");
    law.glint_exponent = p.real("glint_exponent");
    law.min_range = p.real("min_range");
    return std::make_unique<RangeRAdapter>(law);
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("adapt.range_r", trackflow::register_components)
