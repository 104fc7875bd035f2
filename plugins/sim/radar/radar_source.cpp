// Purpose: sim.radar — measures Truth as spherical range/azimuth/elevation(/range rate) with constant bias and Gaussian noise.
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/rng.hpp>

#include <cmath>
#include <string>

namespace trackflow {
namespace {

// Standard deviations of the white noise on each channel for one look.
struct NoiseSigmas {
  double range = 0.0, azimuth = 0.0, elevation = 0.0, range_rate = 0.0;
};

// z_m = h(x) + b + w (paper 001 eq 1-3: r_m = r + r_B + w_r, likewise az, el), w ~ N(0, diag σ²).
// The reported covariance is diag σ²: what the radar adds at random; the biases are a systematic
// error the downstream filter is not told about.
class RadarSource final : public Component {
 public:
  explicit RadarSource(const Params& p)
      : node_(p.node()),
        sensor_position_(p.vec3("position")),
        bias_range_(p.real("bias_range")),
        bias_azimuth_(p.real("bias_azimuth")),
        bias_elevation_(p.real("bias_elevation")),
        every_(p.integer("every")) {
    base_sigmas_ = {p.real("sigma_range"), p.real("sigma_azimuth"), p.real("sigma_elevation"),
                    p.real("sigma_range_rate")};
    convention_ = p.text("azimuth_convention") == "north_clockwise" ? AzimuthConvention::NorthClockwise
                                                                     : AzimuthConvention::XCounterClockwise;
    const bool with_range_rate = p.boolean("range_rate");
    const int n = with_range_rate ? 4 : 3;
    m_.sensor = static_cast<std::uint32_t>(p.integer("sensor_id"));
    m_.frame = Frame::Spherical;
    m_.azimuth = convention_;
    m_.has_range_rate = with_range_rate;
    m_.sensor_position = sensor_position_;
    m_.value = MeasVec::Zero(n);
    m_.covariance = MeasCov::Zero(n, n);
  }

  void start_run(const RunContext& ctx) override {
    rng_.reseed(ctx.seed);
    received_ = 0;
    diagnostics_ = ctx.diagnostics;
  }

  void on_truth(const Truth& t, int) override {
    if (received_++ % every_ != 0) return;
    if (!t.position.allFinite() || !t.velocity.allFinite() || !std::isfinite(t.time)) {
      if (diagnostics_) diagnostics_->skip(node_, "truth at t = " + std::to_string(t.time) + " is not finite; no measurement");
      return;
    }
    // Relative geometry. At the sensor or the zenith the azimuth is undefined and
    // enu_to_spherical returns 0 for it (atan2(0, 0)); range_rate returns |v| at zero range.
    const Vec3 d = t.position - sensor_position_;
    const Vec3 rae = enu_to_spherical(d, convention_);
    const NoiseSigmas s = sigmas_for(rae);
    m_.time = t.time;
    m_.mode = MeasMode::Unknown;
    m_.valid = true;
    m_.value(0) = rae(0) + bias_range_;
    m_.value(1) = rae(1) + bias_azimuth_;
    m_.value(2) = rae(2) + bias_elevation_;
    if (m_.has_range_rate) m_.value(3) = range_rate(d, t.velocity);
    add_noise(s);
    m_.value(1) = wrap_angle(m_.value(1));
    m_.covariance.diagonal()(0) = s.range * s.range;
    m_.covariance.diagonal()(1) = s.azimuth * s.azimuth;
    m_.covariance.diagonal()(2) = s.elevation * s.elevation;
    if (m_.has_range_rate) m_.covariance.diagonal()(3) = s.range_rate * s.range_rate;
    out.emit(m_);
  }

 private:
  // The σ's of this look. Constant now; SNR-dependent noise and noise-scale presets belong here.
  NoiseSigmas sigmas_for(const Vec3& /*range_az_el*/) const { return base_sigmas_; }

  // The only place that draws random numbers; the order (range, az, el, rdot) is part of the
  // output's definition for a given seed. Shot noise would be added here.
  void add_noise(const NoiseSigmas& s) {
    m_.value(0) += s.range * rng_.normal();
    m_.value(1) += s.azimuth * rng_.normal();
    m_.value(2) += s.elevation * rng_.normal();
    if (m_.has_range_rate) m_.value(3) += s.range_rate * rng_.normal();
  }

  std::string node_;
  Vec3 sensor_position_;
  double bias_range_, bias_azimuth_, bias_elevation_;
  long long every_;
  NoiseSigmas base_sigmas_;
  AzimuthConvention convention_;
  Rng rng_;
  long long received_ = 0;
  Diagnostics* diagnostics_ = nullptr;
  Measurement m_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sim.radar";
  d.kind = ComponentKind::Source;
  d.summary = "Simulated radar: Truth -> spherical [range, azimuth, elevation(, range_rate)] with bias and Gaussian noise";
  d.doc = "Measurement model (paper 001 eq 1-3): r_m = r + bias_range + w_r, az_m = wrap(az + bias_azimuth + w_az), "
          "el_m = el + bias_elevation + w_el, rdot_m = rdot + w_rdot, with w ~ N(0, sigma^2) drawn in that order from "
          "the run's seed. Geometry is taken from the target relative to `position` in the pipeline's ENU frame. The "
          "reported covariance is diag(sigma^2): biases are not in it. Range is not clipped at zero, so near the "
          "radar a noisy range can be negative; azimuth is 0 where it is undefined (at the radar, straight overhead).";
  d.params = {
      ParamSpec::real_list("position", dim::length, "radar position in the ENU frame [x east, y north, z up]", 3)
          .def("[0, 0, 0]"),
      ParamSpec::real("sigma_range", dim::length, "range noise standard deviation").def("10 m").at_least(0),
      ParamSpec::real("sigma_azimuth", dim::angle, "azimuth noise standard deviation").def("1 mrad").at_least(0),
      ParamSpec::real("sigma_elevation", dim::angle, "elevation noise standard deviation").def("1 mrad").at_least(0),
      ParamSpec::boolean("range_rate", "also measure range rate (4th element of the value)").def("false"),
      ParamSpec::real("sigma_range_rate", dim::velocity, "range-rate noise standard deviation (when range_rate)")
          .def("1 m/s")
          .at_least(0),
      ParamSpec::real("bias_range", dim::length, "constant range bias added to every measurement").def("0 m"),
      ParamSpec::real("bias_azimuth", dim::angle, "constant azimuth bias").def("0 rad"),
      ParamSpec::real("bias_elevation", dim::angle, "constant elevation bias").def("0 rad"),
      ParamSpec::choice("azimuth_convention", {"north_clockwise", "x_counterclockwise"},
                        "azimuth reference: compass bearing, or math angle from east toward north")
          .def("north_clockwise"),
      ParamSpec::integer("sensor_id", "sensor number written into each measurement").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::integer("every", "measure every N-th truth item received (1: all)").def("1").at_least(1),
  };
  d.accepts = mask(ItemKind::Truth);
  d.min_inputs = 1;
  d.max_inputs = 1;
  d.produces = mask(ItemKind::Measurement);
  d.create = [](const Params& p) { return std::make_unique<RadarSource>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.radar", trackflow::register_components)
