// Purpose: settings of the Cartesian-state radar filters (filter.ekf, filter.ukf; the motion block also filter.imm's modes and filter.track_fusion) — motion and noise model, range-rate use, initialisation — with their parameter declarations and parsing.
#pragma once

#include <trackflow/common_params.hpp>
#include <trackflow/items.hpp>
#include <trackflow/params.hpp>
#include <trackflow/units.hpp>

#include <string>
#include <vector>

namespace trackflow::cartesian_filter {

// The motion and noise model the motion parameters give (motion_param_specs, parse_motion): every
// Cartesian radar filter's, each mode of filter.imm's, and filter.track_fusion's model of its inputs.
struct MotionModel {
  enum class Motion { ConstantVelocity, ConstantAcceleration, Singer } motion = Motion::ConstantVelocity;
  // Continuous: q (CV, m2/s3) or q_jerk (CA, m2/s5); Discrete: sigma_accel; Singer: singer_sigma.
  enum class Noise { Continuous, Discrete, Singer } noise = Noise::Continuous;
  double intensity = 1.0;
  double singer_alpha = 1.0;

  int order() const { return motion == Motion::ConstantVelocity ? 2 : 3; }  // states per axis
  int state_dim() const { return 3 * order(); }
};

struct Settings : MotionModel {
  RangeRateUse range_rate = RangeRateUse::Auto;
  enum class Init { TwoPoint, Explicit, Paper000 } init = Init::TwoPoint;
  // Near the zenith: add the angles' curvature variance to R and drop the azimuth while the
  // zenith lies within 3 sigma (curvature), or the textbook EKF that does neither.
  enum class Zenith { Curvature, Textbook } zenith = Zenith::Curvature;
  Vec3 p0 = Vec3::Zero(), v0 = Vec3::Zero(), a0 = Vec3::Zero();
  double sp0 = 0, sv0 = 0, sa0 = 0;  // initial standard deviations
  std::string type;                  // component type, for messages ("filter.ekf")
  std::string node;
};

// Motion and noise parameters, declared once: every Cartesian radar filter's, each mode of
// filter.imm's and filter.track_fusion's (the model of its inputs).
inline std::vector<ParamSpec> motion_param_specs() {
  return {
      ParamSpec::choice<Settings::Motion>("motion",
                                          {{Settings::Motion::ConstantVelocity, "constant_velocity"},
                                           {Settings::Motion::ConstantAcceleration, "constant_acceleration"},
                                           {Settings::Motion::Singer, "singer"}},
                                          "motion model")
          .def("constant_velocity"),
      ParamSpec::real("q", dim::accel_psd, "constant_velocity: spectral density of the white acceleration noise")
          .def("1 m2/s3")
          .at_least(0),
      ParamSpec::real("q_jerk", dim::jerk_psd,
                      "constant_acceleration: spectral density of the white jerk noise (paper 000 eq 3.19)")
          .def("1 m2/s5")
          .at_least(0),
      ParamSpec::real("sigma_accel", dim::acceleration,
                      "CV/CA discrete white-noise model instead: std of the acceleration (CV) or its increment (CA)")
          .at_least(0),
      ParamSpec::real("singer_alpha", dim::frequency, "singer: inverse correlation time of the acceleration, e.g. 1/s")
          .positive(),
      ParamSpec::real("singer_sigma", dim::acceleration, "singer: standard deviation sigma_m of the acceleration")
          .positive(),
  };
}

inline ParamSpec zenith_param() {
  using Zenith = Settings::Zenith;
  return ParamSpec::choice<Zenith>("zenith", {{Zenith::Curvature, "curvature"}, {Zenith::Textbook, "textbook"}},
                                   "near the zenith: add the angles' curvature variance to R and drop the azimuth within "
                                   "3 sigma of it (curvature), or the textbook EKF (textbook)")
      .def("curvature");
}

inline ParamSpec initial_sigma_acceleration_param() {
  return ParamSpec::real("initial_sigma_acceleration", dim::acceleration,
                         "CA/Singer, two_point or explicit: initial acceleration std (default 50 m/s2; Singer: singer_sigma)")
      .positive();
}

// Motion, noise, range-rate and initialisation parameters every Cartesian radar filter takes.
inline std::vector<ParamSpec> param_specs() {
  std::vector<ParamSpec> specs = motion_param_specs();
  for (ParamSpec& p : std::vector<ParamSpec>{
      range_rate_param(),
      ParamSpec::choice<Settings::Init>("init",
                                        {{Settings::Init::TwoPoint, "two_point"},
                                         {Settings::Init::Explicit, "explicit"},
                                         {Settings::Init::Paper000, "paper000"}},
                                        "two-point differencing, the initial_* values, or paper 000's three-point P0 (§IV.2.1)")
          .def("two_point"),
      ParamSpec::real_list("initial_position", dim::length, "init explicit: position (ENU)", 3),
      ParamSpec::real_list("initial_velocity", dim::velocity, "init explicit: velocity", 3).def("[0, 0, 0]"),
      ParamSpec::real_list("initial_acceleration", dim::acceleration, "init explicit, CA/Singer: acceleration", 3)
          .def("[0, 0, 0]"),
      ParamSpec::real("initial_sigma_position", dim::length, "init explicit: position std").positive(),
      ParamSpec::real("initial_sigma_velocity", dim::velocity, "init explicit: velocity std").positive(),
      initial_sigma_acceleration_param(),
  })
    specs.push_back(std::move(p));
  return specs;
}

// Validates the combination of motion_param_specs() (each one alone was checked by its ParamSpec)
// and sets the motion and noise of `s`.
inline void parse_motion(const Params& p, MotionModel& s) {
  using S = MotionModel;
  s.motion = p.choice<S::Motion>("motion");
  const bool cv = s.motion == S::Motion::ConstantVelocity, ca = s.motion == S::Motion::ConstantAcceleration,
             singer = s.motion == S::Motion::Singer;
  if (!cv && p.given("q"))
    throw p.error("q", "q (m2/s3) is the constant_velocity intensity; constant_acceleration takes q_jerk (m2/s5), "
                       "singer takes singer_alpha and singer_sigma");
  if (!ca && p.given("q_jerk")) throw p.error("q_jerk", "q_jerk is for motion: constant_acceleration");
  if (singer && p.given("sigma_accel"))
    throw p.error("sigma_accel", "sigma_accel is the discrete-noise alternative for constant_velocity and "
                                 "constant_acceleration; the Singer noise is set by singer_sigma");
  for (const char* name : {"singer_alpha", "singer_sigma"}) {
    if (!singer && p.given(name)) throw p.error(name, std::string(name) + " is for motion: singer");
    if (singer && !p.has(name)) throw p.error(name, "required with motion: singer");
  }
  if (p.given("sigma_accel") && (p.given("q") || p.given("q_jerk")))
    throw p.error("sigma_accel", "give either a continuous-noise intensity (q / q_jerk) or sigma_accel, not both");
  if (singer) {
    s.noise = S::Noise::Singer;
    s.intensity = p.real("singer_sigma");
    s.singer_alpha = p.real("singer_alpha");
  } else if (p.given("sigma_accel")) {
    s.noise = S::Noise::Discrete;
    s.intensity = p.real("sigma_accel");
  } else {
    s.intensity = ca ? p.real("q_jerk") : p.real("q");
  }
}

// Validates the combination of the parameters of param_specs().
inline Settings parse_settings(const Params& p, std::string type) {
  using S = Settings;
  S s;
  s.type = std::move(type);
  s.node = p.node();
  parse_motion(p, s);
  const bool cv = s.motion == S::Motion::ConstantVelocity, singer = s.motion == S::Motion::Singer;

  s.range_rate = p.choice<RangeRateUse>("range_rate");
  s.init = p.choice<S::Init>("init");
  const bool expl = s.init == S::Init::Explicit;
  for (const char* name : {"initial_position", "initial_velocity", "initial_acceleration", "initial_sigma_position",
                           "initial_sigma_velocity"})
    if (!expl && p.given(name)) throw p.error(name, std::string(name) + " is only used with init: explicit");
  if (expl)
    for (const char* req : {"initial_position", "initial_sigma_position", "initial_sigma_velocity"})
      if (!p.has(req)) throw p.error(req, "required with init: explicit");
  if (cv && p.given("initial_acceleration"))
    throw p.error("initial_acceleration", "the constant_velocity state has no acceleration");
  if (p.given("initial_sigma_acceleration")) {
    if (cv) throw p.error("initial_sigma_acceleration", "the constant_velocity state has no acceleration");
    if (s.init == S::Init::Paper000)
      throw p.error("initial_sigma_acceleration", "init: paper000 derives the acceleration variance from sigma and T");
  }
  if (expl) {
    s.p0 = p.vec3("initial_position");
    s.v0 = p.vec3("initial_velocity");
    s.a0 = p.vec3("initial_acceleration");
    s.sp0 = p.real("initial_sigma_position");
    s.sv0 = p.real("initial_sigma_velocity");
  }
  // Unknown initial acceleration: Singer's stationary std is the natural prior.
  s.sa0 = p.real_or("initial_sigma_acceleration", singer ? s.intensity : 50.0);
  return s;
}

}  // namespace trackflow::cartesian_filter
