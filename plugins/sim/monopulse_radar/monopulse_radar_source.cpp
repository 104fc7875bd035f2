// Purpose: sim.monopulse_radar — Truth to spherical [range, azimuth, elevation] through paper 003's angle physics: four-horn monopulse, Swerling RCS, glint mixture, radar-equation thermal noise, each switchable.
#include "glint.hpp"
#include "monopulse_antenna.hpp"
#include "process_statistics.hpp"
#include "radar_equation.hpp"
#include "rcs_fluctuation.hpp"

#include <trackflow/common_params.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/rng.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace trackflow {
namespace {

using sim::SwerlingCase;

enum class Antenna { FourHorn, Linear };
enum class GlintAxes { PerPlane, Rotated };
enum class Coupling { Shared, Independent };

double from_db(double db) { return std::pow(10.0, db / 10.0); }

struct MonopulseRunResult final : RunResult {
  sim::ProcessStatistics stats;
  // Its codec under mpirun (run_result_codec.hpp): the statistics go as the struct's bytes (plain
  // numbers, same build on every process), so a field added to them later travels without a change here.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.stats);
  }
};

// Independent streams per effect (derived from the run's seed), so switching one effect off leaves the
// draws of the others unchanged: an ablation compares the same realisations.
enum Stream : std::uint64_t { kRangeStream = 1, kRcsStream = 2, kGlintStream = 3, kThermalStream = 4 };

class MonopulseRadar final : public Component, public FieldListCodec<MonopulseRunResult> {
 public:
  explicit MonopulseRadar(const Params& p)
      : node_(p.node()),
        position_(p.vec3("position")),
        convention_(p.choice<AzimuthConvention>("azimuth_convention")),
        every_(p.integer("every")),
        sigma_range_(p.real("sigma_range")),
        antenna_(p.choice<Antenna>("antenna")),
        monopulse_({p.real("beamwidth_constant"), p.real("squint")}),
        beamwidth_(p.real("beamwidth")),
        pointing_az_(p.real("pointing_error_azimuth")),
        pointing_el_(p.real("pointing_error_elevation")),
        rcs_mean_(from_db(p.real("rcs_mean"))),
        rcs_(p.choice<SwerlingCase>("rcs_model"), p.real("rcs_bandwidth"), p.real("rcs_scan_period")),
        glint_on_(p.boolean("glint")),
        coupled_(p.choice<Coupling>("glint_rcs_coupling") == Coupling::Shared),
        glint_(glint_settings(p)),
        thermal_on_(p.boolean("thermal")),
        detection_threshold_(from_db(p.real("detection_threshold"))) {
    check_choices(p);
    equation_.peak_power = p.real("peak_power");
    equation_.antenna_gain = from_db(p.real("antenna_gain"));
    equation_.wavelength = p.real("wavelength");
    equation_.noise_temperature = p.real("noise_temperature");
    equation_.bandwidth = p.real("receiver_bandwidth");
    equation_.noise_figure = from_db(p.real("noise_figure"));
    equation_.losses = from_db(p.real("losses"));
    equation_.integration_gain = from_db(p.real("integration_gain"));
    // The thermal law needs the slope of the antenna actually modelled; the linear antenna is the
    // four-horn's tangent at boresight, so both see the same thermal noise.
    slope_ = std::abs(monopulse_.slope());
    m_.sensor = static_cast<std::uint32_t>(p.integer("sensor_id"));
    m_.frame = Frame::Spherical;
    m_.azimuth = convention_;
    m_.mode = MeasMode::Skin;
    m_.sensor_position = position_;
    m_.value = MeasVec::Zero(3);
    m_.covariance = MeasCov::Zero(3, 3);
    m_.covariance(0, 0) = sq(p.real("reported_sigma_range"));
    m_.covariance(1, 1) = sq(p.real("reported_sigma_azimuth"));
    m_.covariance(2, 2) = sq(p.real("reported_sigma_elevation"));
  }

  void start_run(const RunContext& ctx) override {
    rng_range_.reseed(derive_seed(ctx.seed, kRangeStream, "range"));
    rng_rcs_.reseed(derive_seed(ctx.seed, kRcsStream, "rcs"));
    rng_glint_.reseed(derive_seed(ctx.seed, kGlintStream, "glint"));
    rng_thermal_.reseed(derive_seed(ctx.seed, kThermalStream, "thermal"));
    received_ = 0;
    started_ = false;
    diagnostics_ = ctx.diagnostics;
    run_ = sim::ProcessStatistics{};
  }

  void on_truth(const Truth& t, int) override {
    if (received_++ % every_ != 0) return;
    if (!t.position.allFinite() || !std::isfinite(t.time)) {
      if (diagnostics_) diagnostics_->skip(node_, "truth at t = " + std::to_string(t.time) + " is not finite; no measurement");
      return;
    }
    const Vec3 rae = spherical(t.position - position_);
    const double range = rae(0);
    advance_target(t.time);

    // Apparent direction: the glint displaces the echo's phase centre by g metres across the line of
    // sight, an angle g / r (eq 3-11), in each plane.
    const double glint_az = glint_on_ ? glint_.azimuth_m() / range : 0.0;
    const double glint_el = glint_on_ ? glint_.elevation_m() / range : 0.0;
    // The antenna points pointing_error off the target; the target's apparent offset from boresight,
    // in beamwidths, is what the horns see.
    const double u_az = (glint_az - pointing_az_) / beamwidth_;
    const double u_el = (glint_el - pointing_el_) / beamwidth_;
    double e_az = u_az, e_el = u_el;  // linear antenna: the error signal is the offset itself
    bool in_beam = true;
    if (antenna_ == Antenna::FourHorn) {
      const sim::MonopulseChannels c = monopulse_.channels(u_az, u_el);
      in_beam = c.sum > 0.0 && std::isfinite(c.sum);
      // In slope units, so that the thermal noise below is added on the same scale for both antennas.
      e_az = in_beam ? c.azimuth / c.sum / monopulse_.slope() : 0.0;
      e_el = in_beam ? c.elevation / c.sum / monopulse_.slope() : 0.0;
    }

    bool detected = in_beam;
    m_.has_snr = thermal_on_;
    if (thermal_on_) {
      const double snr = equation_.snr(rcs_mean_ * rcs_.factor(), std::max(range, 1.0));
      m_.snr_db = 10.0 * std::log10(std::max(snr, 1e-300));
      detected = detected && snr >= detection_threshold_;
      const double s = sim::error_signal_sigma(std::max(snr, 1e-300)) / slope_;
      const double n_az = rng_thermal_.normal(), n_el = rng_thermal_.normal();
      // A missed look carries no thermal draw into its value (it is flagged invalid; filters coast).
      if (detected) {
        e_az += s * n_az;
        e_el += s * n_el;
      }
    }

    ++run_.looks;
    run_.missed += !detected;
    m_.time = t.time;
    m_.origin = t.target;  // for scoring: which truth this detection comes from
    m_.valid = detected;
    m_.value(0) = range + sigma_range_ * rng_range_.normal();
    // Measured angle = boresight (true + pointing error) + the reported offset in beamwidths.
    m_.value(1) = wrap_angle(rae(1) + pointing_az_ + e_az * beamwidth_);
    m_.value(2) = rae(2) + pointing_el_ + e_el * beamwidth_;
    out.emit(m_);
  }

 private:
  static double sq(double x) { return x * x; }

  // enu_to_spherical with sqrt in place of hypot (no overflow is possible at radar distances; hypot is
  // the costliest call per look). Same conventions, atan2(0, 0) = 0 at the zenith and the radar.
  Vec3 spherical(const Vec3& d) const {
    const double h2 = d.x() * d.x() + d.y() * d.y();
    const double horizontal = std::sqrt(h2);
    const double az = convention_ == AzimuthConvention::NorthClockwise ? std::atan2(d.x(), d.y()) : std::atan2(d.y(), d.x());
    return {std::sqrt(h2 + d.z() * d.z()), az, std::atan2(d.z(), horizontal)};
  }

  static sim::GlintSettings glint_settings(const Params& p) {
    sim::GlintSettings s;
    s.sigma = p.real("glint_factor") * p.real("target_length");
    s.laplace_weight = p.real("glint_laplace_weight");
    s.variance_ratio = p.real("glint_variance_ratio");
    s.bandwidth = p.real("glint_bandwidth");
    s.per_plane = p.choice<GlintAxes>("glint_axes") == GlintAxes::PerPlane;
    return s;
  }

  // Parameters of a switched-off effect would be silently ignored: refuse them.
  static void check_choices(const Params& p) {
    const auto model = p.choice<SwerlingCase>("rcs_model");
    if (p.given("rcs_scan_period") && model != SwerlingCase::One && model != SwerlingCase::Three)
      throw p.error("rcs_scan_period", "is used by rcs_model swerling1 and swerling3 only (scan-to-scan fluctuation)");
    if (p.given("rcs_bandwidth") && model == SwerlingCase::Constant)
      throw p.error("rcs_bandwidth", "is not used with rcs_model: constant");
    if (!p.boolean("glint"))
      for (const char* name : {"target_length", "glint_factor", "glint_laplace_weight", "glint_variance_ratio",
                               "glint_bandwidth", "glint_axes", "glint_rcs_coupling"})
        if (p.given(name)) throw p.error(name, "is set but glint is false");
    if (!p.boolean("thermal"))
      for (const char* name : {"peak_power", "antenna_gain", "wavelength", "noise_temperature", "receiver_bandwidth",
                               "noise_figure", "losses", "integration_gain", "detection_threshold"})
        if (p.given(name)) throw p.error(name, "is set but thermal is false");
    if (p.choice<Antenna>("antenna") == Antenna::Linear)
      for (const char* name : {"beamwidth_constant", "squint"})
        if (p.given(name)) throw p.error(name, "shapes the four-horn antenna; antenna: linear has no horns");
  }

  // The RCS evolves at every look (its own stream); the glint renews with the DAR(1) rule, sharing the
  // RCS's uniform when coupled. The processes' sums feed the summary's closed-form checks.
  void advance_target(double t) {
    const double g_prev = glint_.linear(), x_prev = rcs_.factor();
    bool renewed = true;
    if (!started_) {
      rcs_.start(t, rng_rcs_);
      if (glint_on_) glint_.start(fade(), rng_glint_);
    } else {
      rcs_.advance(t, rng_rcs_);
      if (glint_on_) renewed = glint_.advance(std::max(0.0, t - last_time_), [this] { return fade(); }, rng_glint_);
    }
    const double x = rcs_.factor();
    run_.x += x;
    run_.x2 += x * x;
    if (glint_on_) {
      const double g = glint_.linear();
      ++run_.glint_n;
      run_.g2 += g * g;
      run_.g4 += g * g * g * g;
      run_.renewals += renewed;
      run_.laplacian_renewals += renewed && glint_.laplacian();
      if (started_) {
        run_.g_lag += g * g_prev;
        run_.g_prev2 += g_prev * g_prev;
      }
    }
    if (started_) {
      ++run_.pairs;
      run_.time_steps += t - last_time_;
      run_.x_lag += x * x_prev;
      run_.x_prev += x_prev;
      run_.x_cur_paired += x;
    }
    started_ = true;
    last_time_ = t;
  }

  double fade() const { return coupled_ ? rcs_.uniform() : std::numeric_limits<double>::quiet_NaN(); }

 public:
  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<MonopulseRunResult>();
    r->stats = run_;
    return r;
  }

  void merge(RunResult& result) override { total_.add(static_cast<const MonopulseRunResult&>(result).stats); }

  void finish(Summary& s, const FinishContext&) override {
    const sim::ProcessStatistics& t = total_;
    s.metric("looks", static_cast<double>(t.looks));
    s.metric("missed_fraction", t.looks ? static_cast<double>(t.missed) / static_cast<double>(t.looks) : 0.0);
    // Published whether or not the effect is on (NaN when there is nothing to estimate), so a check on
    // them fails rather than naming a metric that does not exist.
    s.metric("glint_variance", t.glint_variance(), "m2");
    s.metric("glint_kurtosis", t.glint_kurtosis());
    s.metric("glint_lag1_correlation", t.glint_lag1());
    s.metric("glint_correlation_time", sim::ProcessStatistics::correlation_time(t.glint_lag1(), t.mean_step()), "s");
    s.metric("glint_laplacian_fraction", t.renewals ? static_cast<double>(t.laplacian_renewals) / static_cast<double>(t.renewals)
                                                    : sim::ProcessStatistics::nan());
    s.metric("rcs_factor_mean", t.rcs_mean());
    s.metric("rcs_factor_variance", t.rcs_variance());
    s.metric("rcs_lag1_correlation", rcs_.fluctuating() ? t.rcs_lag1() : sim::ProcessStatistics::nan());
    s.metric("reported_sigma_azimuth", std::sqrt(m_.covariance(1, 1)), "rad");
    s.metric("reported_sigma_elevation", std::sqrt(m_.covariance(2, 2)), "rad");
    s.notes.push_back("pooled over all looks of all runs: glint_variance = mean g^2 of the linear glint (closed form: "
                      "(glint_factor L)^2), glint_kurtosis = mean g^4 / (mean g^2)^2 (3 for a Gaussian; the mixture's tails raise "
                      "it), glint_lag1_correlation = sum g_k g_k-1 / sum g_k-1^2 (exp(-2 pi B dt)), "
                      "glint_correlation_time = -dt / ln(lag-1) (1 / (2 pi B)); rcs_factor_* of RCS / mean (Swerling "
                      "I/II: mean 1, variance 1; III/IV: 1, 1/2; lag-1 correlation exp(-4 pi B dt) per look); "
                      "missed_fraction = looks below detection_threshold");
  }

 private:
  std::string node_;
  Vec3 position_;
  AzimuthConvention convention_;
  long long every_;
  double sigma_range_;
  Antenna antenna_;
  sim::FourHornMonopulse monopulse_;
  double beamwidth_, pointing_az_, pointing_el_;
  double rcs_mean_;
  sim::RcsFluctuation rcs_;
  bool glint_on_, coupled_;
  sim::GlintProcess glint_;
  bool thermal_on_;
  double detection_threshold_;
  sim::RadarEquation equation_;
  double slope_ = 1.0;
  Rng rng_range_, rng_rcs_, rng_glint_, rng_thermal_;
  long long received_ = 0;
  bool started_ = false;
  double last_time_ = 0.0;
  Diagnostics* diagnostics_ = nullptr;
  Measurement m_;
  sim::ProcessStatistics run_, total_;
};

const char* const kDoc =
    "Paper 003 (Song 2017) angle measurement of a skin-tracked target. Per look at the truth's range r, azimuth and "
    "elevation (relative to `position`): the target's RCS fluctuates (rcs_model: Swerling I-IV with the Lorentzian "
    "spectrum of eq 3-15, half-power bandwidth rcs_bandwidth, mean rcs_mean in dBsm; I and III hold per "
    "rcs_scan_period); the glint (glint: true) displaces the echo's phase centre by a linear glint g drawn from the "
    "Gaussian/Laplacian mixture of eq 3-9 (weight glint_laplace_weight, Laplacian variance glint_variance_ratio x the "
    "Gaussian's, total RMS glint_factor x target_length, Table 1) with the Lorentzian spectrum of eq 3-10 "
    "(glint_bandwidth), generated exactly by DAR(1) renewal, rotated by alpha ~ U(0, 2 pi) into the azimuth and "
    "elevation planes (Fig 18; glint_axes: per_plane gives each plane the RMS glint_factor x L, rotated gives the "
    "rotated glint that RMS) and divided by r (eq 3-11). With glint_rcs_coupling: shared the Laplacian's scale comes "
    "from the same uniform variate as the RCS (E = -ln F(x), so large glint coincides with RCS fades; Fig 9c), "
    "independent draws it separately (Fig 9b). The antenna (antenna: four_horn, eq 2-1..2-12, beamwidth_constant "
    "k = 1.19, squint 0.358 beamwidths) points at the true direction plus pointing_error_*; the target's apparent "
    "offset from boresight u (beamwidths) gives the error signals d_az/S, d_el/S, which the receiver divides by the "
    "boresight slope (|k_m| = 1.049 per beamwidth for the AN/FPS-16 constants): off boresight the reported offset "
    "differs from u (the non-linear error); antenna: linear reports u exactly. Thermal noise (thermal: true): "
    "SNR = P_t G^2 lambda^2 sigma / ((4 pi)^3 k T_e B F R^4) (eq 4.1) with the fluctuating RCS, times "
    "integration_gain over losses; each error signal gets N(0, 1/(2 SNR)), an angle noise "
    "beamwidth / (|k_m| sqrt(2 SNR)) (paper 001 eq 6-8's law); a look below detection_threshold is a missed "
    "detection: valid = false (filters coast), value without thermal noise. Measured angle = true + pointing error "
    "+ reported offset x beamwidth; range = r + N(0, sigma_range^2) (the paper treats range as perfectly tracked). "
    "The measurement reports the constant covariance diag(reported_sigma_*^2): what a fixed-R filter assumes "
    "(adapt.range_r replaces the angle part). snr_db is the look's SNR when thermal is on. Random draws come from "
    "four streams derived from the run's seed (range, RCS, glint, thermal), so switching one effect off leaves the "
    "others' realisations unchanged. Equations, choices and tests: docs/filters.md, docs/papers/003-monopulse-glint.md.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sim.monopulse_radar";
  d.kind = ComponentKind::Source;
  d.summary = "Simulated monopulse tracking radar (paper 003): four-horn antenna, Swerling RCS, glint mixture, "
              "radar-equation thermal noise, each switchable";
  d.doc = kDoc;
  d.params = {
      ParamSpec::real_list("position", dim::length, "radar position in the ENU frame [x east, y north, z up]", 3)
          .def("[0, 0, 0]"),
      azimuth_convention_param("azimuth reference: compass bearing, or math angle from east toward north"),
      ParamSpec::integer("sensor_id", "sensor number written into each measurement").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::integer("every", "measure every N-th truth item received (1: all)").def("1").at_least(1),
      ParamSpec::real("sigma_range", dim::length, "range noise standard deviation (white Gaussian)").def("1 m").at_least(0),
      ParamSpec::real("reported_sigma_range", dim::length, "range sigma in the reported covariance").def("1 m").positive(),
      ParamSpec::real("reported_sigma_azimuth", dim::angle, "azimuth sigma in the reported covariance (a fixed-R filter's R)")
          .def("100 urad")
          .positive()
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      ParamSpec::real("reported_sigma_elevation", dim::angle, "elevation sigma in the reported covariance")
          .def("100 urad")
          .positive()
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      ParamSpec::choice<Antenna>("antenna", {{Antenna::FourHorn, "four_horn"}, {Antenna::Linear, "linear"}},
                                 "four-horn amplitude comparison (eq 2-1..2-12, non-linear off boresight) or an ideal "
                                 "linear discriminator")
          .def("four_horn"),
      // A tracking antenna's pencil beam: 0.2-5 deg in practice (AN/FPS-16 1.1 deg); eq 2-1's
      // Gaussian-like pattern is a small-angle model, so past 30 deg it no longer describes a
      // monopulse antenna (issue 27: 1e6 deg was accepted).
      ParamSpec::real("beamwidth", dim::angle,
                      "3 dB beamwidth theta_B, at most 30 deg (a pencil beam; not in the paper; AN/FPS-16: 1.1 deg)")
          .def("1.1 deg")
          .positive()
          .at_most(30.0 * std::numbers::pi / 180.0),
      ParamSpec::real("beamwidth_constant", dim::none, "four_horn: k_theta of eq 2-1 (AN/FPS-16: 1.19)")
          .def("1.19")
          .positive()
          .at_most(10),
      ParamSpec::real("squint", dim::none, "four_horn: squint angle in beamwidths (AN/FPS-16: 0.358)").def("0.358").positive().at_most(2),
      ParamSpec::real("pointing_error_azimuth", dim::angle, "boresight minus true azimuth (servo lag); off boresight the "
                                                             "four-horn's error is non-linear")
          .def("0 rad"),
      ParamSpec::real("pointing_error_elevation", dim::angle, "boresight minus true elevation").def("0 rad"),
      ParamSpec::choice<SwerlingCase>("rcs_model",
                                      {{SwerlingCase::Constant, "constant"},
                                       {SwerlingCase::One, "swerling1"},
                                       {SwerlingCase::Two, "swerling2"},
                                       {SwerlingCase::Three, "swerling3"},
                                       {SwerlingCase::Four, "swerling4"}},
                                      "RCS fluctuation: none, or Swerling I/II (exponential) or III/IV (chi-square 4 dof); "
                                      "I/III hold per scan")
          .def("swerling2"),
      ParamSpec::real("rcs_mean", dim::decibel, "mean RCS in dBsm (paper: 5.6, KSLV-II)").def("5.6 dB").at_least(-100).at_most(100),
      ParamSpec::real("rcs_bandwidth", dim::frequency,
                      "half-power bandwidth B of the RCS spectrum eq 3-15 (I/Q components; not in the paper: 2 L w / "
                      "lambda, the echo's Doppler spread, is ~8 Hz for 47.5 m pitching at 0.25 deg/s at C band)")
          .def("10 Hz")
          .positive(),
      ParamSpec::real("rcs_scan_period", dim::time, "swerling1/3: the fluctuation holds over a scan of this length")
          .def("1 s")
          .positive(),
      ParamSpec::boolean("glint", "add glint (eq 3-9..3-11)").def("true"),
      ParamSpec::real("target_length", dim::length, "glint: target length L (KSLV-I: 47.5 m)").def("47.5 m").positive(),
      ParamSpec::real("glint_factor", dim::none, "glint: RMS glint / L (Table 1: 0.35, 0.2 rectangle, 0.18, 0.1)")
          .def("0.2")
          .at_least(0)
          .at_most(10),
      ParamSpec::real("glint_laplace_weight", dim::none, "glint: mixing weight i of the Laplacian in eq 3-9 (not in the "
                                                         "paper; 0.5 reproduces its 9.5^2 = 0.5 * 1.787 + 0.5 * 178.7)")
          .def("0.5")
          .at_least(0)
          .at_most(1),
      ParamSpec::real("glint_variance_ratio", dim::none, "glint: Laplacian variance / Gaussian variance (paper: 100)")
          .def("100")
          .positive()
          .at_most(1e6),
      ParamSpec::real("glint_bandwidth", dim::frequency,
                      "glint: half-power bandwidth B of eq 3-10 (not in the paper; as rcs_bandwidth)")
          .def("10 Hz")
          .positive(),
      ParamSpec::choice<GlintAxes>("glint_axes", {{GlintAxes::PerPlane, "per_plane"}, {GlintAxes::Rotated, "rotated"}},
                                   "glint: the RMS is per plane (Table 1's sigma = R/sqrt(2)) or of the rotated glint")
          .def("per_plane"),
      ParamSpec::choice<Coupling>("glint_rcs_coupling", {{Coupling::Shared, "shared"}, {Coupling::Independent, "independent"}},
                                  "glint: Laplacian scale from the RCS's uniform variate (one random source, Fig 9c) or "
                                  "its own (Fig 9b)")
          .def("shared"),
      ParamSpec::boolean("thermal", "add thermal noise from the radar equation (eq 4.1)").def("true"),
      ParamSpec::real("peak_power", dim::none, "thermal: peak transmit power P_t in W (AN/FPS-16: 500e3)").def("500e3").positive(),
      ParamSpec::real("antenna_gain", dim::decibel, "thermal: antenna gain G (41 dB)").def("41 dB").at_least(-50).at_most(100),
      ParamSpec::real("wavelength", dim::length, "thermal: wavelength lambda (the paper prints c/500 Hz; C band c/5.5 GHz = 54.55 mm)")
          .def("54.55 mm")
          .positive(),
      ParamSpec::real("noise_temperature", dim::none, "thermal: noise temperature T_e in K (290)").def("290").positive(),
      ParamSpec::real("receiver_bandwidth", dim::frequency, "thermal: receiver bandwidth B (8 MHz)").def("8 MHz").positive(),
      ParamSpec::real("noise_figure", dim::decibel, "thermal: noise figure F (12 dB)").def("12 dB").at_least(0).at_most(100),
      ParamSpec::real("losses", dim::decibel, "thermal: system losses (not in eq 4.1)").def("0 dB").at_least(0).at_most(100),
      ParamSpec::real("integration_gain", dim::decibel,
                      "thermal: SNR gain of the pulses integrated into one angle measurement (eq 4.1 is one pulse)")
          .def("0 dB")
          .at_least(0)
          .at_most(200),
      ParamSpec::real("detection_threshold", dim::decibel, "thermal: looks with a lower SNR are missed (valid = false)")
          .def("13 dB")
          .at_least(-200)
          .at_most(300),
  };
  d.accepts = mask(ItemKind::Truth);
  d.min_inputs = 1;
  d.max_inputs = 1;
  d.produces = mask(ItemKind::Measurement);
  d.produces_frames = mask(Frame::Spherical);
  d.create = [](const Params& p) { return std::make_unique<MonopulseRadar>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.monopulse_radar", trackflow::register_components)
