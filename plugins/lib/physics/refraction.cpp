// Purpose: the exponential-atmosphere ray trace and the shared refraction parameters (declaration and reading).
#include "refraction.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace trackflow::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// 8-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 4> kNodes = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                          0.9602898564975363};
constexpr std::array<double, 4> kWeights = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                            0.1012285362903763};

// Below the lowest apparent elevation the ray is taken as not reaching the target.
constexpr double kLowestApparent = 0.2 * kDeg;

}  // namespace

double ExponentialAtmosphere::central_angle(double apparent, double h) const {
  const double N = n0 * 1e-6;
  auto n_at = [&](double height) { return 1.0 + N * std::exp(-height / scale_height); };
  const double r0 = earth_radius + radar_height;
  const double c = n_at(radar_height) * r0 * std::cos(apparent);
  auto integrand = [&](double height) {
    const double r = earth_radius + height, nr = n_at(height) * r;
    return c / (r * std::sqrt((nr - c) * (nr + c)));
  };
  // Layers growing geometrically from the radar: fine where the refractivity and the ray's slope
  // change fast (the lowest kilometres at low elevation), coarse above. Above 30 scale heights
  // n - 1 < 1e-16 and the rest of the path is the straight line of vacuum, in closed form.
  const double top = std::min(h, 30.0 * scale_height);
  double psi = 0.0, lo = radar_height, width = 25.0;
  while (lo < top) {
    const double hi = std::min(top, lo + width);
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    double sum = 0.0;
    for (size_t i = 0; i < kNodes.size(); ++i)
      sum += kWeights[i] * (integrand(mid - half * kNodes[i]) + integrand(mid + half * kNodes[i]));
    psi += half * sum;
    lo = hi;
    width *= 1.6;
  }
  if (h > top) {
    const double r_top = earth_radius + top, r_t = earth_radius + h;
    psi += std::acos(c / r_t) - std::acos(c / r_top);
  }
  return psi;
}

double ExponentialAtmosphere::bias(const Vec3& relative) const {
  const double r0 = earth_radius + radar_height;
  const Vec3 q = relative + Vec3(0.0, 0.0, r0);
  const double horizontal = std::hypot(relative.x(), relative.y());
  const double psi_t = std::atan2(horizontal, q.z());
  const double h_t = q.norm() - earth_radius;
  const double theta = std::atan2(relative.z(), horizontal);
  if (!(h_t > radar_height) || !(psi_t > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // Secant on a -> psi(a, h_t) - psi_t, decreasing in a, from the geometric elevation and a Snell
  // estimate; converges in 3-5 steps to 1e-13 rad.
  const double N = n0 * 1e-6;
  double a0 = std::max(theta, kLowestApparent), a1 = a0 + 0.8 * N / std::tan(std::max(theta, 1.0 * kDeg));
  double f0 = central_angle(a0, h_t) - psi_t, f1 = central_angle(a1, h_t) - psi_t;
  for (int k = 0; k < 40 && std::abs(a1 - a0) > 1e-14; ++k) {
    if (f1 == f0) break;
    const double a2 = a1 - f1 * (a1 - a0) / (f1 - f0);
    a0 = a1;
    f0 = f1;
    a1 = std::clamp(a2, 0.5 * kLowestApparent, 0.5 * std::numbers::pi - 1e-9);
    f1 = central_angle(a1, h_t) - psi_t;
  }
  if (!(a1 >= kLowestApparent) || std::abs(f1) > 1e-11) return std::numeric_limits<double>::quiet_NaN();
  return a1 - theta;
}

double ElevationBias::bias(const Vec3& relative, double elevation, bool& defined) const {
  switch (kind) {
    case RefractionKind::None:
      defined = true;
      return 0.0;
    case RefractionKind::Clark:
      defined = clark.defined(elevation);
      return defined ? clark.bias(elevation) : 0.0;
    case RefractionKind::Exponential: {
      const double b = exponential.bias(relative);
      defined = std::isfinite(b);
      return defined ? b : 0.0;
    }
  }
  defined = false;
  return 0.0;
}

ParamSpec refraction_kind_param(const char* doc) {
  return ParamSpec::choice<RefractionKind>(
             "refraction",
             {{RefractionKind::None, "none"}, {RefractionKind::Clark, "clark"}, {RefractionKind::Exponential, "exponential"}},
             doc)
      .def("none");
}

ParamSpec n0_param() {
  return ParamSpec::real("n0", dim::none, "surface refractivity N0 in N-units (n = 1 + N0 1e-6 at the radar; paper 004: 312.5)")
      .def("312.5")
      .at_least(0)
      .at_most(1000);
}

std::vector<ParamSpec> clark_param_specs(bool with_below) {
  std::vector<ParamSpec> s = {
      ParamSpec::real_list("clark_coefficients", dim::none,
                           "Clark's beta1 = c1 - c2/u + c3/u^2 - c4/u^3, [c1, c2, c3, c4] (paper 004, c3 and c4 as printed)", 4)
          .def("[1.03585796, 1.072014e-2, 1.279119e-8, 1.227363e-8]"),
      ParamSpec::choice<ClarkThetaUnit>("clark_theta_unit",
                                        {{ClarkThetaUnit::Radian, "rad"}, {ClarkThetaUnit::Degree, "deg"}},
                                        "the unit u = theta takes inside beta1 (the paper does not say): rad gives "
                                        "beta1(10 deg) = 0.974, deg 1.035")
          .def("rad"),
  };
  if (with_below)
    s.push_back(ParamSpec::choice<ClarkBelow>("clark_below_2deg",
                                              {{ClarkBelow::Invalid, "invalid"},
                                               {ClarkBelow::Hold, "hold"},
                                               {ClarkBelow::Extrapolate, "extrapolate"}},
                                              "below 2 deg, where Clark is undefined: the value is invalid, b is held at "
                                              "b(2 deg), or the 2-10 deg formula is extrapolated")
                    .def("invalid"));
  return s;
}

std::vector<ParamSpec> exponential_param_specs() {
  return {
      ParamSpec::real("scale_height", dim::length,
                      "exponential: refractivity scale height H, N(h) = N0 exp(-h/H) (CRPL exponential for N0 = 313: 7 km)")
          .def("7 km")
          .positive(),
      ParamSpec::real("earth_radius", dim::length, "exponential: radius of the stratified sphere").def("6371 km").positive(),
  };
}

ClarkModel read_clark(const Params& p, bool with_below) {
  ClarkModel m;
  m.n0 = p.real("n0");
  const auto& c = p.reals("clark_coefficients");
  m.c1 = c[0];
  m.c2 = c[1];
  m.c3 = c[2];
  m.c4 = c[3];
  m.unit = p.choice<ClarkThetaUnit>("clark_theta_unit");
  if (with_below) m.below = p.choice<ClarkBelow>("clark_below_2deg");
  // beta1 must stay positive over 2-10 deg, or b changes sign inside Clark's own range.
  if (m.beta1(ClarkModel::kLow) <= 0.0 || m.beta1(ClarkModel::kHigh) <= 0.0)
    throw p.error("clark_coefficients", "these coefficients make beta1 <= 0 within 2-10 deg (check clark_theta_unit)");
  return m;
}

ElevationBias read_elevation_bias(const Params& p, double radar_height) {
  ElevationBias e;
  e.kind = p.choice<RefractionKind>("refraction");
  const bool clark = e.kind == RefractionKind::Clark, expo = e.kind == RefractionKind::Exponential;
  for (const char* name : {"clark_coefficients", "clark_theta_unit", "clark_below_2deg"})
    if (!clark && p.given(name)) throw p.error(name, std::string(name) + " is for refraction: clark");
  for (const char* name : {"scale_height", "earth_radius"})
    if (!expo && p.given(name)) throw p.error(name, std::string(name) + " is for refraction: exponential");
  if (e.kind == RefractionKind::None && p.given("n0")) throw p.error("n0", "n0 is set but refraction is none");
  if (clark) e.clark = read_clark(p, true);
  if (expo) {
    e.exponential.n0 = p.real("n0");
    e.exponential.scale_height = p.real("scale_height");
    e.exponential.earth_radius = p.real("earth_radius");
    e.exponential.radar_height = radar_height;
  }
  return e;
}

}  // namespace trackflow::sim
