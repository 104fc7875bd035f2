// Purpose: the kinematic transition model of a Cartesian state (constant velocity, constant acceleration, Singer; continuous or discrete noise) — one value, and one parameter block declared, parsed and validated here for every filter, IMM mode and fusion node.
#pragma once

#include <trackflow/params.hpp>

#include <string>
#include <vector>

namespace trackflow {

// What the analyst's `motion`, `q` / `q_jerk` / `sigma_accel` / `singer_alpha` / `singer_sigma`
// describe. The state is motion.hpp's per-axis layout [x vx (ax) y vy (ay) z vz (az)], ENU.
struct TransitionModel {
  enum class Motion { ConstantVelocity, ConstantAcceleration, Singer } motion = Motion::ConstantVelocity;
  // Continuous: white noise on the highest derivative with spectral density `intensity` (CV q in
  // m2/s3, CA q_jerk in m2/s5); Discrete: piecewise-constant noise of std `intensity` (sigma_accel);
  // Singer: `intensity` is sigma_m (m/s2), `singer_alpha` the inverse correlation time (1/s).
  enum class Noise { Continuous, Discrete, Singer } noise = Noise::Continuous;
  double intensity = 1.0;
  double singer_alpha = 1.0;

  int order() const { return motion == Motion::ConstantVelocity ? 2 : 3; }  // states per axis
  int state_dim() const { return 3 * order(); }
  bool operator==(const TransitionModel&) const = default;

  // "constant_velocity, q 1 m2/s3": the model in the analyst's words, for messages.
  std::string text() const;
};

// The models a node offers; the parameter block declares only what they need.
struct TransitionChoices {
  bool constant_velocity = true;
  bool constant_acceleration = true;
  bool singer = true;
  bool discrete_noise = true;  // sigma_accel, for constant velocity and acceleration
  TransitionModel::Motion default_motion = TransitionModel::Motion::ConstantVelocity;
  std::string singer_alpha_default;  // empty: singer_alpha is required with motion: singer

  static TransitionChoices constant_velocity_only();
  static TransitionChoices singer_only(std::string alpha_default);
};

// The block's declarations: motion, then q (CV), q_jerk (CA), sigma_accel, singer_alpha,
// singer_sigma, each only where `choices` offer it.
std::vector<ParamSpec> transition_param_specs(const TransitionChoices& choices = {});

// Validates the combination (each value alone was checked by its ParamSpec) and returns the model.
// The refusals point at the offending parameter's line.
TransitionModel parse_transition(const Params& p, const TransitionChoices& choices = {});

// Whether the analyst wrote any parameter of the block (a node that may take its inputs' model).
bool transition_given(const Params& p);

}  // namespace trackflow
