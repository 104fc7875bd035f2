// Purpose: the transition model's parameter block: declarations, validation of the combination, the model in words.
#include <trackflow/number_text.hpp>
#include <trackflow/transition_model.hpp>
#include <trackflow/units.hpp>

#include <initializer_list>
#include <string>
#include <utility>

namespace trackflow {
namespace {

using Motion = TransitionModel::Motion;
using Noise = TransitionModel::Noise;

const char* word(Motion m) {
  switch (m) {
    case Motion::ConstantVelocity: return "constant_velocity";
    case Motion::ConstantAcceleration: return "constant_acceleration";
    case Motion::Singer: return "singer";
  }
  return "?";
}

bool offered(const TransitionChoices& c, Motion m) {
  return m == Motion::ConstantVelocity ? c.constant_velocity
         : m == Motion::ConstantAcceleration ? c.constant_acceleration
                                             : c.singer;
}

// "constant_acceleration takes q_jerk (m2/s5), singer takes singer_alpha and singer_sigma": what
// each offered motion other than `m` takes, for the refusal of a parameter given with `m`.
std::string others_take(const TransitionChoices& c, Motion m) {
  std::string s;
  auto add = [&](Motion o, const char* what) {
    if (o == m || !offered(c, o)) return;
    s += (s.empty() ? "" : ", ");
    s += std::string(word(o)) + " takes " + what;
  };
  add(Motion::ConstantVelocity, "q (m2/s3)");
  add(Motion::ConstantAcceleration, "q_jerk (m2/s5)");
  add(Motion::Singer, "singer_alpha and singer_sigma");
  return s;
}

std::string number(double v) { return number_text::general(v, 6); }

}  // namespace

std::string TransitionModel::text() const {
  std::string s = word(motion);
  if (motion == Motion::Singer)
    return s + ", singer_alpha " + number(singer_alpha) + " 1/s, singer_sigma " + number(intensity) + " m/s2";
  if (noise == Noise::Discrete) return s + ", sigma_accel " + number(intensity) + " m/s2";
  return s + (motion == Motion::ConstantVelocity ? ", q " + number(intensity) + " m2/s3"
                                                 : ", q_jerk " + number(intensity) + " m2/s5");
}

TransitionChoices TransitionChoices::constant_velocity_only() {
  TransitionChoices c;
  c.constant_acceleration = c.singer = false;
  return c;
}

TransitionChoices TransitionChoices::singer_only(std::string alpha_default) {
  TransitionChoices c;
  c.constant_velocity = c.constant_acceleration = c.discrete_noise = false;
  c.default_motion = Motion::Singer;
  c.singer_alpha_default = std::move(alpha_default);
  return c;
}

std::vector<ParamSpec> transition_param_specs(const TransitionChoices& c) {
  std::vector<std::pair<Motion, const char*>> words;
  for (Motion m : {Motion::ConstantVelocity, Motion::ConstantAcceleration, Motion::Singer})
    if (offered(c, m)) words.emplace_back(m, word(m));
  std::vector<std::string> names;
  std::vector<int> values;
  for (const auto& [m, w] : words) names.push_back(w), values.push_back(static_cast<int>(m));
  ParamSpec motion = ParamSpec::choice_words("motion", std::move(names), "motion model").def(word(c.default_motion));
  motion.choice_values = std::move(values);

  std::vector<ParamSpec> specs;
  specs.push_back(std::move(motion));
  if (c.constant_velocity)
    specs.push_back(ParamSpec::real("q", dim::accel_psd, "constant_velocity: spectral density of the white acceleration noise")
                        .def("1 m2/s3")
                        .at_least(0));
  if (c.constant_acceleration)
    specs.push_back(ParamSpec::real("q_jerk", dim::jerk_psd,
                                    "constant_acceleration: spectral density of the white jerk noise (paper 000 eq 3.19)")
                        .def("1 m2/s5")
                        .at_least(0));
  if (c.discrete_noise && (c.constant_velocity || c.constant_acceleration))
    specs.push_back(ParamSpec::real("sigma_accel", dim::acceleration,
                                    c.constant_acceleration
                                        ? "CV/CA discrete white-noise model instead: std of the acceleration (CV) or its increment (CA)"
                                        : "discrete white-noise model instead: std of the acceleration, every axis")
                        .at_least(0));
  if (c.singer) {
    ParamSpec alpha = ParamSpec::real("singer_alpha", dim::frequency, "singer: inverse correlation time of the acceleration, e.g. 1/s")
                          .positive();
    if (!c.singer_alpha_default.empty()) alpha = std::move(alpha).def(c.singer_alpha_default);
    specs.push_back(std::move(alpha));
    ParamSpec sigma = ParamSpec::real("singer_sigma", dim::acceleration, "singer: standard deviation sigma_m of the acceleration")
                          .positive();
    // With Singer the only motion the parameter is always needed; otherwise only with motion: singer.
    if (!c.constant_velocity && !c.constant_acceleration) sigma = std::move(sigma).req();
    specs.push_back(std::move(sigma));
  }
  return specs;
}

TransitionModel parse_transition(const Params& p, const TransitionChoices& c) {
  TransitionModel s;
  s.motion = p.choice<Motion>("motion");
  const bool cv = s.motion == Motion::ConstantVelocity, ca = s.motion == Motion::ConstantAcceleration,
             singer = s.motion == Motion::Singer;
  const bool declared_q = c.constant_velocity, declared_q_jerk = c.constant_acceleration, declared_singer = c.singer,
             declared_sigma_accel = c.discrete_noise && (c.constant_velocity || c.constant_acceleration);
  if (declared_q && !cv && p.given("q"))
    throw p.error("q", "q (m2/s3) is the constant_velocity intensity; " + others_take(c, Motion::ConstantVelocity));
  if (declared_q_jerk && !ca && p.given("q_jerk")) throw p.error("q_jerk", "q_jerk is for motion: constant_acceleration");
  if (declared_sigma_accel && singer && p.given("sigma_accel"))
    throw p.error("sigma_accel", "sigma_accel is the discrete-noise alternative for constant_velocity and "
                                 "constant_acceleration; the Singer noise is set by singer_sigma");
  if (declared_singer)
    for (const char* name : {"singer_alpha", "singer_sigma"}) {
      if (!singer && p.given(name)) throw p.error(name, std::string(name) + " is for motion: singer");
      if (singer && !p.has(name)) throw p.error(name, "required with motion: singer");
    }
  const bool discrete = declared_sigma_accel && p.given("sigma_accel");
  if (discrete && ((declared_q && p.given("q")) || (declared_q_jerk && p.given("q_jerk"))))
    throw p.error("sigma_accel", "give either a continuous-noise intensity (" +
                                     std::string(declared_q && declared_q_jerk ? "q / q_jerk" : declared_q ? "q" : "q_jerk") +
                                     ") or sigma_accel, not both");
  if (singer) {
    s.noise = Noise::Singer;
    s.intensity = p.real("singer_sigma");
    s.singer_alpha = p.real("singer_alpha");
  } else if (discrete) {
    s.noise = Noise::Discrete;
    s.intensity = p.real("sigma_accel");
  } else {
    s.intensity = ca ? p.real("q_jerk") : p.real("q");
  }
  return s;
}

bool transition_given(const Params& p) {
  for (const char* name : {"motion", "q", "q_jerk", "sigma_accel", "singer_alpha", "singer_sigma"})
    if (p.given(name)) return true;
  return false;
}

}  // namespace trackflow
