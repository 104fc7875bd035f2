// Purpose: settings of the Cartesian-state radar filters (filter.ekf, filter.ukf, filter.imm's record modes) — the transition model (trackflow/transition_model.hpp), range-rate use, initialisation — with their parameter declarations and parsing.
#pragma once

#include <trackflow/common_params.hpp>
#include <trackflow/items.hpp>
#include <trackflow/params.hpp>
#include <trackflow/transition_model.hpp>
#include <trackflow/units.hpp>

#include <string>
#include <vector>

namespace trackflow::cartesian_filter {

struct Settings : TransitionModel {
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
  std::vector<ParamSpec> specs = transition_param_specs();
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

// Validates the combination of the parameters of param_specs().
inline Settings parse_settings(const Params& p, std::string type) {
  using S = Settings;
  S s;
  s.type = std::move(type);
  s.node = p.node();
  static_cast<TransitionModel&>(s) = parse_transition(p);
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
