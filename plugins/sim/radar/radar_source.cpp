// Purpose: sim.radar — measures Truth as spherical range/azimuth/elevation(/range rate) with bias, modelled noise, shot bursts and mode/lock schedules.
#include "physics/geodesy.hpp"
#include "physics/refraction.hpp"
#include "noise_model.hpp"
#include "shot_noise.hpp"
#include "time_windows.hpp"

#include <trackflow/common_params.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/rng.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace trackflow {
namespace {

using sim::NoiseSigmas;

enum class ReportedNoise { Actual, Nominal };

// A radar at a geodetic site measures its angles from its own horizon. Within this angle of arc
// of the frame's origin (about 1 km) its axes are taken as the frame's (a level sensor, as
// before sites away from the origin were possible); beyond it, its measurements carry its own
// east/north/up axes (Measurement::sensor_axes).
constexpr double kMaxSiteTilt = 0.01 * std::numbers::pi / 180.0;  // rad

struct RadarPlace {
  Vec3 position = Vec3::Zero();
  double height = 0.0;  // above the ellipsoid (site) or the frame's origin (position z)
  bool level = true;
  Mat3 axes = Mat3::Identity();  // the radar's east, north, up in the frame's axes (when not level)
};

// `position` in the frame, or `site` among the pipeline's geodetic sites.
RadarPlace radar_place(const Params& p) {
  if (!p.given("site")) {
    const Vec3 pos = p.vec3("position");
    return {pos, pos.z()};
  }
  if (p.given("position")) throw p.error("position", "give either 'position' (ENU) or 'site' (geodetic), not both");
  const std::vector<sim::Site> sites = sim::read_sites(p);
  const sim::Site site = sim::find_site(p, sites, "site");
  const sim::EnuFrame frame = sim::EnuFrame::from_params(p, sites, "site");
  const double tilt = std::acos(std::clamp(frame.up_at(site.where).z(), -1.0, 1.0));
  RadarPlace place{frame.to_enu(site.where), site.where.height};
  if (tilt > kMaxSiteTilt) {
    place.level = false;
    place.axes = frame.axes_at(site.where);
  }
  return place;
}

// Per-run count of measurements the refraction model left undefined (flagged invalid).
struct RadarRunResult final : RunResult {
  std::uint64_t refraction_invalid = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.refraction_invalid);
  }
};

// A shot_* parameter written while shot noise is off would be silently ignored.
void check_shot_params(const Params& p, const sim::ShotNoise& shot) {
  if (!shot.enabled) {
    for (const char* name : {"shot_length", "shot_period", "shot_magnitude", "shot_offset"})
      if (p.given(name)) throw p.error(name, "is set but shot_noise is false; add 'shot_noise: true'");
    return;
  }
  if (shot.length > shot.period)
    throw p.error("shot_length", "(" + std::to_string(shot.length) + ") must not exceed shot_period (" +
                                     std::to_string(shot.period) + ")");
}

// z_m = h(x) + b + w (paper 001 eq 1-3: r_m = r + r_B + w_r, likewise az, el), w ~ N(0, diag σ²).
// The reported covariance is diag σ² of the σ's this look used, except that a shot-noise
// burst is not in it (the radar does not know); the biases are a systematic error the
// downstream filter is not told about.
class RadarSource final : public Component, public FieldListCodec<RadarRunResult> {
 public:
  explicit RadarSource(const Params& p)
      : node_(p.node()),
        place_(radar_place(p)),
        sensor_position_(place_.position),
        refraction_(sim::read_elevation_bias(p, place_.height)),
        bias_range_(p.real("bias_range")),
        bias_azimuth_(p.real("bias_azimuth")),
        bias_elevation_(p.real("bias_elevation")),
        every_(p.integer("every")),
        noise_(p),
        modes_(p, "mode_schedule", true),
        unlocked_(p, "invalid_schedule", false),
        default_mode_(p.choice<MeasMode>("default_mode")) {
    report_nominal_ = p.choice<ReportedNoise>("reported_noise") == ReportedNoise::Nominal;
    if (report_nominal_ && noise_.scale() == 0.0) throw p.error("noise_factor", "must not be 0 with reported_noise: nominal");
    shot_.enabled = p.boolean("shot_noise");
    shot_.length = p.integer("shot_length");
    shot_.period = p.integer("shot_period");
    shot_.offset = p.has("shot_offset") ? p.integer("shot_offset") : shot_.period;
    shot_.magnitude = p.real("shot_magnitude");
    check_shot_params(p, shot_);
    convention_ = p.choice<AzimuthConvention>("azimuth_convention");
    const bool with_range_rate = p.boolean("range_rate");
    const int n = with_range_rate ? 4 : 3;
    m_.sensor = static_cast<std::uint32_t>(p.integer("sensor_id"));
    m_.frame = Frame::Spherical;
    m_.azimuth = convention_;
    m_.has_range_rate = with_range_rate;
    m_.sensor_position = sensor_position_;
    m_.sensor_level = place_.level;
    m_.sensor_axes = place_.axes;
    m_.value = MeasVec::Zero(n);
    m_.covariance = MeasCov::Zero(n, n);
  }

  void start_run(const RunContext& ctx) override {
    rng_.reseed(ctx.seed);
    refraction_invalid_ = 0;
    received_ = 0;
    emitted_ = 0;
    diagnostics_ = ctx.diagnostics;
  }

  void on_truth(const Truth& t, int) override {
    // (every = 1, the default, skips the division.)
    if (every_ != 1 && received_++ % every_ != 0) return;
    if (!t.position.allFinite() || !t.velocity.allFinite() || !std::isfinite(t.time)) {
      if (diagnostics_) diagnostics_->skip(node_, "truth at t = " + std::to_string(t.time) + " is not finite; no measurement");
      return;
    }
    // Relative geometry. At the sensor or the zenith the azimuth is undefined and
    // enu_to_spherical returns 0 for it (atan2(0, 0)); range_rate returns |v| at zero range.
    // In the radar's own axes (its horizon) when its site is tilted against the frame.
    const Vec3 d = place_.level ? Vec3(t.position - sensor_position_) : Vec3(place_.axes.transpose() * (t.position - sensor_position_));
    const Vec3 rae = enu_to_spherical(d, convention_);
    const sim::TimeWindow* window = modes_.find(t.time);
    const NoiseSigmas nominal = sigmas_for(rae, window);
    m_.time = t.time;
    m_.origin = t.target;  // for scoring: which truth this detection comes from
    m_.mode = window ? window->mode : default_mode_;
    m_.valid = unlocked_.find(t.time) == nullptr;
    m_.value(0) = rae(0) + bias_range_;
    m_.value(1) = rae(1) + bias_azimuth_;
    m_.value(2) = rae(2) + bias_elevation_;
    // Refraction bends the ray up: the radar sees the target b above its geometric elevation.
    // Skipped entirely when off, so the output is unchanged (signed zeros included).
    if (refraction_.kind != sim::RefractionKind::None) {
      bool defined = true;
      m_.value(2) += refraction_.bias(d, rae(2), defined);
      if (!defined) {
        m_.valid = false;
        ++refraction_invalid_;
      }
    }
    if (m_.has_range_rate)
      m_.value(3) = range_rate(d, place_.level ? t.velocity : Vec3(place_.axes.transpose() * t.velocity));
    add_noise(nominal.scaled(shot_.factor(emitted_)));
    m_.value(1) = wrap_angle(m_.value(1));
    // reported_noise: nominal — a degraded radar that does not know it is degraded reports
    // the sigma before noise_factor x noise_preset (paper 001 SCN.2/3).
    const NoiseSigmas reported = report_nominal_ ? nominal.scaled(1.0 / noise_.scale()) : nominal;
    m_.covariance.diagonal()(0) = reported.range * reported.range;
    m_.covariance.diagonal()(1) = reported.azimuth * reported.azimuth;
    m_.covariance.diagonal()(2) = reported.elevation * reported.elevation;
    if (m_.has_range_rate) m_.covariance.diagonal()(3) = reported.range_rate * reported.range_rate;
    ++emitted_;
    out.emit(m_);
  }

  std::unique_ptr<RunResult> end_run() override {
    if (refraction_.kind == sim::RefractionKind::None) return nullptr;
    auto r = std::make_unique<RadarRunResult>();
    r->refraction_invalid = refraction_invalid_;
    return r;
  }
  void merge(RunResult& r) override { total_refraction_invalid_ += static_cast<RadarRunResult&>(r).refraction_invalid; }
  void finish(Summary& s, const FinishContext&) override {
    if (refraction_.kind == sim::RefractionKind::None) return;
    s.metric("refraction_invalid", static_cast<double>(total_refraction_invalid_));
    if (total_refraction_invalid_)
      s.notes.push_back(std::to_string(total_refraction_invalid_) +
                        " measurement(s) flagged invalid where the refraction model is undefined (Clark below 2 deg "
                        "with clark_below_2deg: invalid, or no ray reaches the target)");
  }

 private:
  // The σ's of this look as the radar knows them: the noise model's (which, for the snr model,
  // draws the SNR jitter and sets the SNR), replaced channel by channel by the mode window's
  // overrides, then multiplied by the noise scale.
  NoiseSigmas sigmas_for(const Vec3& range_az_el, const sim::TimeWindow* window) {
    const sim::Look look = noise_.look(range_az_el(0), rng_);
    m_.has_snr = look.has_snr;
    m_.snr_db = look.snr_db;
    NoiseSigmas s = look.sigmas;
    if (window) {
      s.range = window->sigma_range.value_or(s.range);
      s.azimuth = window->sigma_azimuth.value_or(s.azimuth);
      s.elevation = window->sigma_elevation.value_or(s.elevation);
      s.range_rate = window->sigma_range_rate.value_or(s.range_rate);
    }
    return s.scaled(noise_.scale());
  }

  // With sigmas_for, the only place that draws random numbers: the order (range, az, el, rdot)
  // is part of the output's definition for a given seed. Whatever the σ's (bursts, windows,
  // presets), the same standard normals are drawn, so those options never shift the sequence.
  void add_noise(const NoiseSigmas& s) {
    m_.value(0) += s.range * rng_.normal();
    m_.value(1) += s.azimuth * rng_.normal();
    m_.value(2) += s.elevation * rng_.normal();
    if (m_.has_range_rate) m_.value(3) += s.range_rate * rng_.normal();
  }

  std::string node_;
  RadarPlace place_;
  Vec3 sensor_position_;
  sim::ElevationBias refraction_;
  std::uint64_t refraction_invalid_ = 0, total_refraction_invalid_ = 0;
  double bias_range_, bias_azimuth_, bias_elevation_;
  long long every_;
  sim::NoiseModel noise_;
  sim::TimeWindows modes_;
  sim::TimeWindows unlocked_;
  MeasMode default_mode_;
  sim::ShotNoise shot_;
  AzimuthConvention convention_;
  bool report_nominal_ = false;
  Rng rng_;
  long long received_ = 0;
  long long emitted_ = 0;  // measurements of this run so far: the shot-noise sample index
  Diagnostics* diagnostics_ = nullptr;
  Measurement m_;
};

std::vector<ParamSpec> window_fields(bool with_mode) {
  std::vector<ParamSpec> f = {
      ParamSpec::real("start", dim::time, "first time in the window (inclusive)").req(),
      ParamSpec::real("end", dim::time, "end of the window (exclusive), after start").req(),
  };
  if (!with_mode) return f;
  f.push_back(ParamSpec::choice<MeasMode>("mode", {{MeasMode::Beacon, "beacon"}, {MeasMode::Skin, "skin"}},
                                          "tracking mode written into measurements in this window")
                  .req());
  f.push_back(ParamSpec::real("sigma_range", dim::length, "range sigma in this window (default: the noise model's)").at_least(0));
  f.push_back(ParamSpec::real("sigma_azimuth", dim::angle, "azimuth sigma in this window (default: the noise model's)").at_least(0)
                  .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint));
  f.push_back(ParamSpec::real("sigma_elevation", dim::angle, "elevation sigma in this window (default: the noise model's)").at_least(0)
                  .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint));
  f.push_back(ParamSpec::real("sigma_range_rate", dim::velocity, "range-rate sigma in this window (default: the noise model's)")
                  .at_least(0));
  return f;
}

const char* const kDoc =
    "Measurement model (paper 001 eq 1-3): r_m = r + bias_range + w_r, az_m = wrap(az + bias_azimuth + w_az), "
    "el_m = el + bias_elevation + w_el, rdot_m = rdot + w_rdot, w ~ N(0, sigma^2). Geometry is taken from the target "
    "relative to `position` in the pipeline's ENU frame. Range is not clipped at zero, so near the radar a noisy range "
    "can be negative; azimuth is 0 where it is undefined (at the radar, straight overhead); elevation is not folded.\n"
    "Noise sigmas (noise_model): constant = sigma_range/azimuth/elevation. snr = paper 001 eq 6-8, "
    "sigma_r = range_resolution / sqrt(2 SNR), sigma_az = beamwidth_azimuth / (monopulse_slope sqrt(2 SNR)), sigma_el "
    "likewise with beamwidth_elevation, SNR linear; SNR(dB) = snr_reference - 10 n log10(R / snr_reference_range) + "
    "snr_jitter N(0,1), n = 4 (snr_law radar_r4: skin echo, two-way radar equation) or n = 2 (beacon_r2: a "
    "transponder, each leg of the link is one-way, as paper 001's radar beacon system; paper 001 uses 3 dB jitter). "
    "R is taken as at least 1 m and SNR is held within [-200, 300] dB so sigma stays finite. table4 = paper 000 Table 4 "
    "(S/N 45 dB: 0.3 m, 50 urad up to 158.48 km; 29 dB: 1.9 m, 320 urad at 1000 km; 25.47 dB: 3 m, 500 urad at "
    "1500 km; 22.97 dB: 4.3 m, 630 urad at 2000 km): between rows sigma is a power law in range (log-log) and S/N "
    "linear in log range, which is exact for the table's own R^-2 S/N; held at the first row below 158.48 km and at "
    "the last beyond 2000 km. snr and table4 set the measurement's snr_db; sigma_range_rate is used in every model.\n"
    "Noise scale: every sigma (all channels, all models, mode-window overrides included) is multiplied by "
    "noise_factor x noise_preset (best 0.5, none/normal 1, worst 2; paper 000 Table 15); noise_factor 5 and 10 are "
    "paper 001's SCN.2 and SCN.3. The factors scale sigma, not the reported SNR.\n"
    "Shot noise (paper 000 Case 1, Table 15: a 10-sample burst of noise 10^6 times the reference noise, every 4000 "
    "samples): in a burst every channel's sigma is multiplied by shot_magnitude. The paper gives the burst's \"size\" "
    "in the same words as the 0.5x/1x/2x presets, which scale sigma, so the magnitude multiplies sigma, not the "
    "variance. Samples are this radar's measurements in a run, counted from 0; bursts start at shot_offset "
    "(default: one shot_period in, so the first samples are clean), shot_offset + shot_period, ... The reported "
    "covariance keeps the nominal sigma: the radar does not know about the burst.\n"
    "Schedules: mode_schedule windows [start, end) set the measurement's mode (beacon/skin) and may override sigmas "
    "(replacing the noise model's, before the noise scale); outside them the mode is default_mode. Measurements inside "
    "an invalid_schedule window have valid = false (radar not locked; filters coast) but still carry a finite noisy "
    "value. Windows of one schedule must not overlap.\n"
    "Random draws, per emitted measurement, from the run's seed: for noise_model snr one standard normal for the SNR "
    "jitter (drawn even when snr_jitter is 0), then one each for range, azimuth, elevation and, if measured, range "
    "rate. Bursts, schedules, presets and factors only change the sigma multiplying these draws, so they never shift "
    "the sequence. Truth items skipped by `every` or for being non-finite draw nothing.\n"
    "Refraction (paper 004; off by default): the elevation gets b(el) on top of bias_elevation, el the geometric "
    "elevation, before the noise. clark: b = N0 1e-6 cot(el) above 10 deg, times beta1(u) = c1 - c2/u + c3/u^2 - c4/u^3 "
    "for 2-10 deg, u = el in clark_theta_unit; below 2 deg clark_below_2deg says whether the measurement is flagged "
    "invalid (the default: Clark is undefined there and the radar's elevation unreliable), b is held at b(2 deg), or "
    "the formula is extrapolated. exponential: the apparent elevation of the ray traced through n(h) = 1 + N0 1e-6 "
    "exp(-h/scale_height) over a sphere of earth_radius, from the radar's height (its site's, else position z) to the "
    "target; flagged invalid where no ray reaches it. Range delay is not modelled. The summary counts the "
    "measurements flagged invalid by the model (refraction_invalid). b is measured from the radar's horizon: "
    "with site, from the radar's own horizon.\n"
    "Geodetic placement: site names one of the pipeline's sites: (WGS-84 latitude, longitude, height), placed in the "
    "ENU frame anchored at pipeline.frame_origin; azimuth and elevation are measured from the site's own horizon "
    "(its east, north, up). Within 0.01 deg of arc of the origin these are taken as the frame's axes; farther away "
    "(1 deg of arc per ~111 km) each measurement carries the radar's axes (a tilted sensor), which filter.ekf, "
    "filter.ukf and the sinks that place measurements in the frame use, and other consumers refuse.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sim.radar";
  d.kind = ComponentKind::Source;
  d.summary = "Simulated radar: Truth -> spherical [range, azimuth, elevation(, range_rate)] with bias and constant, "
              "SNR or Table-4 noise, noise presets, shot bursts, beacon/skin and lock schedules";
  d.doc = kDoc;
  d.params = {
      ParamSpec::real_list("position", dim::length, "radar position in the ENU frame [x east, y north, z up]", 3)
          .def("[0, 0, 0]"),
      ParamSpec::string("site", "instead of position: the radar's geodetic site, one of the pipeline's sites: (it "
                                "measures from its own horizon there)"),
      sim::sites_param(),
      sim::frame_origin_param(),
      sim::refraction_kind_param("tropospheric refraction bias added to the elevation: none, Clark's model (paper 004) "
                                 "or an exponential atmosphere ray-traced"),
      sim::n0_param(),
      ParamSpec::choice<sim::NoiseModelKind>("noise_model",
                                             {{sim::NoiseModelKind::Constant, "constant"},
                                              {sim::NoiseModelKind::Snr, "snr"},
                                              {sim::NoiseModelKind::Table4, "table4"}},
                        "where sigma comes from: the sigma_* values, the SNR link budget (paper 001 eq 6-8), or "
                        "paper 000 Table 4 over range")
          .def("constant"),
      ParamSpec::real("sigma_range", dim::length, "constant model: range noise standard deviation").def("10 m").at_least(0),
      ParamSpec::real("sigma_azimuth", dim::angle, "constant model: azimuth noise standard deviation").def("1 mrad").at_least(0)
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      ParamSpec::real("sigma_elevation", dim::angle, "constant model: elevation noise standard deviation")
          .def("1 mrad")
          .at_least(0)
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
      ParamSpec::boolean("range_rate", "also measure range rate (4th element of the value)").def("false"),
      ParamSpec::real("sigma_range_rate", dim::velocity, "range-rate noise standard deviation (when range_rate; all models)")
          .def("1 m/s")
          .at_least(0),
      ParamSpec::real("range_resolution", dim::length, "snr model: range resolution delta_r").def("15 m").positive(),
      ParamSpec::real("beamwidth_azimuth", dim::angle, "snr model: azimuth beamwidth").def("2 deg").positive(),
      ParamSpec::real("beamwidth_elevation", dim::angle, "snr model: elevation beamwidth").def("2 deg").positive(),
      ParamSpec::real("monopulse_slope", dim::none, "snr model: monopulse sum/difference slope k_m").def("1.6").positive(),
      ParamSpec::real("snr_reference", dim::decibel, "snr model: SNR at snr_reference_range")
          .def("30 dB")
          .at_least(-200)
          .at_most(300),
      ParamSpec::real("snr_reference_range", dim::length, "snr model: range of snr_reference").def("10 km").positive(),
      ParamSpec::choice<sim::SnrLaw>("snr_law", {{sim::SnrLaw::RadarR4, "radar_r4"}, {sim::SnrLaw::BeaconR2, "beacon_r2"}},
                        "snr model: SNR falls as R^-4 (skin echo) or R^-2 (beacon/transponder, one-way legs)")
          .def("radar_r4"),
      ParamSpec::real("snr_jitter", dim::decibel, "snr model: standard deviation of the per-measurement SNR error (paper 001: 3 dB)")
          .def("0 dB")
          .at_least(0)
          .at_most(30),
      ParamSpec::real("noise_factor", dim::none, "multiplies every sigma (degraded operation: paper 001 SCN.2 x5, SCN.3 x10)")
          .def("1")
          .at_least(0)
          .at_most(1e6),
      ParamSpec::choice<sim::NoisePreset>("noise_preset",
                                          {{sim::NoisePreset::None, "none"},
                                           {sim::NoisePreset::Best, "best"},
                                           {sim::NoisePreset::Normal, "normal"},
                                           {sim::NoisePreset::Worst, "worst"}},
                        "paper 000 noise scale: best 0.5x, normal 1x, worst 2x sigma, times noise_factor")
          .def("none"),
      ParamSpec::choice<ReportedNoise>("reported_noise", {{ReportedNoise::Actual, "actual"}, {ReportedNoise::Nominal, "nominal"}},
                        "covariance reported with each measurement: the sigma actually used, or the sigma before "
                        "noise_factor x noise_preset (a degraded radar that does not know it)")
          .def("actual"),
      ParamSpec::boolean("shot_noise", "add shot-noise bursts (paper 000 Case 1)").def("false"),
      ParamSpec::integer("shot_length", "shot noise: samples per burst (paper: 10)").def("10").at_least(1),
      ParamSpec::integer("shot_period", "shot noise: samples from one burst start to the next (paper: 4000)")
          .def("4000")
          .at_least(1),
      ParamSpec::real("shot_magnitude", dim::none, "shot noise: sigma multiplier in a burst (paper: 10^6)")
          .def("1e6")
          .at_least(0)
          .at_most(1e12),
      ParamSpec::integer("shot_offset", "shot noise: sample index of the first burst (default: shot_period)").at_least(0),
      ParamSpec::records("mode_schedule", window_fields(true),
                         "windows {start, end, mode: beacon|skin, optional sigma_range/azimuth/elevation/range_rate}"),
      ParamSpec::choice<MeasMode>("default_mode",
                                  {{MeasMode::Unknown, "unknown"}, {MeasMode::Beacon, "beacon"}, {MeasMode::Skin, "skin"}},
                                  "mode of measurements outside mode_schedule windows")
          .def("unknown"),
      ParamSpec::records("invalid_schedule", window_fields(false),
                         "windows {start, end} in which measurements are flagged valid = false (radar not locked)"),
      ParamSpec::real("bias_range", dim::length, "constant range bias added to every measurement").def("0 m"),
      ParamSpec::real("bias_azimuth", dim::angle, "constant azimuth bias").def("0 rad"),
      ParamSpec::real("bias_elevation", dim::angle, "constant elevation bias").def("0 rad"),
      azimuth_convention_param("azimuth reference: compass bearing, or math angle from east toward north"),
      ParamSpec::integer("sensor_id", "sensor number written into each measurement").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::integer("every", "measure every N-th truth item received (1: all)").def("1").at_least(1),
  };
  for (auto& spec : sim::clark_param_specs(true)) d.params.push_back(std::move(spec));
  for (auto& spec : sim::exponential_param_specs()) d.params.push_back(std::move(spec));
  d.accepts = mask(ItemKind::Truth);
  d.min_inputs = 1;
  d.max_inputs = 1;
  d.produces = mask(ItemKind::Measurement);
  d.produces_frames = mask(Frame::Spherical);
  d.create = [](const Params& p) { return std::make_unique<RadarSource>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.radar", trackflow::register_components)
