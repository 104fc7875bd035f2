// Purpose: tropospheric refraction bias on radar elevation — Clark's model (paper 004) with its derivatives, and an exponential atmosphere ray-traced — with the parameters every node that uses them declares.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/params.hpp>

#include <cmath>
#include <numbers>
#include <vector>

namespace trackflow::sim {

// The unit theta takes inside beta1 (paper 004 does not say; docs/papers/004-refraction-bias.md).
enum class ClarkThetaUnit { Radian, Degree };
// Below 2 deg Clark's model is undefined (paper 004 §2.1.2). invalid: the value is unusable (a
// radar flags the measurement invalid, a corrector passes it on invalid); hold: b(theta) = b(2 deg);
// extrapolate: the 2-10 deg formula is used below 2 deg as well.
enum class ClarkBelow { Invalid, Hold, Extrapolate };

// Paper 004 §2.1.2, N = N0 1e-6:
//   b(theta) = N cot(theta)                 10 deg < theta < 90 deg
//   b(theta) = N cot(theta) beta1(u)        2 deg < theta <= 10 deg
//   beta1 = c1 - c2/u + c3/u^2 - c4/u^3,  u = s theta (s = 1 for radians, 180/pi for degrees).
// With beta2 = c2/u^2 - 2 c3/u^3 + 3 c4/u^4 and beta3 = -2 c2/u^3 + 6 c3/u^4 - 12 c4/u^5 (the
// paper's beta2, beta3), d beta1/d theta = s beta2 and d2 beta1/d theta2 = s^2 beta3, so
//   b'  = N (-csc^2 beta1 + s cot beta2)
//   b'' = N (2 csc^2 cot beta1 - 2 s csc^2 beta2 + s^2 cot beta3)
// (paper 004 eq for b-dot = b' theta-dot, and d b-dot/d theta = b'' theta-dot: the paper prints the
// latter without theta-dot). Above 10 deg beta1 = 1, beta2 = beta3 = 0. theta in rad everywhere.
struct ClarkModel {
  double n0 = 312.5;
  double c1 = 1.03585796, c2 = 1.072014e-2, c3 = 1.279119e-8, c4 = 1.227363e-8;
  ClarkThetaUnit unit = ClarkThetaUnit::Radian;
  ClarkBelow below = ClarkBelow::Invalid;
  static constexpr double kLow = 2.0 * std::numbers::pi / 180.0;    // rad
  static constexpr double kHigh = 10.0 * std::numbers::pi / 180.0;  // rad

  double scale() const { return unit == ClarkThetaUnit::Degree ? 180.0 / std::numbers::pi : 1.0; }
  double beta1(double theta) const {
    const double u = scale() * theta;
    return c1 - c2 / u + c3 / (u * u) - c4 / (u * u * u);
  }
  double beta2(double theta) const {
    const double u = scale() * theta;
    return c2 / (u * u) - 2 * c3 / (u * u * u) + 3 * c4 / (u * u * u * u);
  }
  double beta3(double theta) const {
    const double u = scale() * theta, u2 = u * u;
    return -2 * c2 / (u2 * u) + 6 * c3 / (u2 * u2) - 12 * c4 / (u2 * u2 * u);
  }
  // False where b is not available: below 2 deg with below = invalid, and at or above 90 deg.
  bool defined(double theta) const {
    return theta < std::numbers::pi / 2 && (theta > kLow || below != ClarkBelow::Invalid);
  }
  // The elevation at which the formula is evaluated: below 2 deg, hold evaluates at 2 deg. The
  // extrapolated formula is kept away from u -> 0 (0.1 deg) so it stays finite.
  double evaluation_point(double theta) const {
    if (theta > kLow) return theta;
    return below == ClarkBelow::Hold ? kLow : std::max(theta, 0.1 * std::numbers::pi / 180.0);
  }
  // b, db/dtheta, d2b/dtheta2 at theta (rad); derivatives are 0 where b is held.
  struct Value {
    double b = 0.0, db = 0.0, d2b = 0.0;
  };
  Value at(double theta) const {
    const bool held = theta <= kLow && below == ClarkBelow::Hold;
    const double t = evaluation_point(theta);
    const double N = n0 * 1e-6, cot = 1.0 / std::tan(t), csc2 = 1.0 + cot * cot;
    Value v;
    if (t > kHigh) {
      v.b = N * cot;
      v.db = -N * csc2;
      v.d2b = 2 * N * csc2 * cot;
    } else {
      const double s = scale(), b1 = beta1(t), b2 = beta2(t), b3 = beta3(t);
      v.b = N * cot * b1;
      v.db = N * (-csc2 * b1 + s * cot * b2);
      v.d2b = N * (2 * csc2 * cot * b1 - 2 * s * csc2 * b2 + s * s * cot * b3);
    }
    if (held) v.db = v.d2b = 0.0;
    return v;
  }
  double bias(double theta) const { return at(theta).b; }
};

// Ray tracing through a spherically stratified exponential atmosphere, n(h) = 1 + N0 1e-6 e^(-h/H),
// over a sphere of radius R (Bean & Dutton 1966): the ray leaving the radar (height h_r) at the
// apparent elevation a keeps n r cos(elevation) = n(h_r) (R + h_r) cos(a) (Bouguer), and turns
// through the central angle psi(r) = integral c / (r sqrt(n^2 r^2 - c^2)) dr. The apparent
// elevation of a target is the a whose ray reaches the target's radius at the target's central
// angle; the elevation bias is a minus the geometric elevation.
struct ExponentialAtmosphere {
  double n0 = 312.5;
  double scale_height = 7.0e3;  // m
  double earth_radius = 6371.0e3;  // m
  double radar_height = 0.0;       // m above the sphere

  // Bias for a target at `relative` (ENU from the radar, its up along the local vertical). NaN
  // when the ray cannot reach it (a target below about 0.5 deg of apparent elevation or below the radar).
  double bias(const Vec3& relative) const;
  // The central angle a ray of apparent elevation `apparent` has turned through at height `h`.
  double central_angle(double apparent, double h) const;
};

enum class RefractionKind { None, Clark, Exponential };

// What a node that simulates or scores refraction holds: the model and its parameters.
struct ElevationBias {
  RefractionKind kind = RefractionKind::None;
  ClarkModel clark;
  ExponentialAtmosphere exponential;
  // Bias on the elevation of a target at `relative` (ENU from the radar) whose geometric elevation
  // is `elevation`; `defined` false where the model gives none (Clark below 2 deg, invalid; a
  // ray that does not reach the target).
  double bias(const Vec3& relative, double elevation, bool& defined) const;
};

// Parameter declarations, the same names in every node:
//   refraction (none|clark|exponential), n0, clark_coefficients, clark_theta_unit, clark_below_2deg,
//   scale_height, earth_radius.
ParamSpec refraction_kind_param(const char* doc);
ParamSpec n0_param();
std::vector<ParamSpec> clark_param_specs(bool with_below);
std::vector<ParamSpec> exponential_param_specs();
// Reads a Clark model (n0, clark_*); refuses clark_* parameters when `used` is false.
ClarkModel read_clark(const Params& p, bool with_below);
// Reads `refraction` and the parameters of the chosen model, refusing those of the other.
ElevationBias read_elevation_bias(const Params& p, double radar_height);

}  // namespace trackflow::sim
