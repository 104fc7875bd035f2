// Purpose: moments of the spherical->ENU map under Gaussian (r, az, el) errors and the three statistical conversions built on them.
#pragma once

// Shared, header-only, by convert.debiased, convert.unbiased and convert.unbiased_modified so
// that each formula exists once. Derivation and sources: docs/converters.md.
//
// Notation. The measured point m = (r, az, el) and the true point t differ by independent
// zero-mean Gaussian errors with variances (σr², σa², σe²). p(r, az, el) = r·u(az, el) is the
// sensor-relative ENU position, u = (cos el·h(az), sin el) with h the horizontal unit vector
// of the azimuth convention: north_clockwise h = (sin az, cos az), x_counterclockwise
// h = (cos az, sin az) (geometry.hpp, azimuth_basis). h' = dh/daz is h rotated by -90° or +90°.
//
// Everything follows from three facts about w ~ N(0, σ²) (Mo et al. 1998, eq 12):
//   E[cos w] = λ = exp(-σ²/2),  E[sin w] = 0,  E[cos 2w] = λ⁴,  E[sin 2w] = 0.
// Hence for any unit vector rotating with the angle, E[h(az + w)] = λ·h(az) and
//   Cov[h(az + w)] = (1-λ²)²/2 · h hᵀ + (1-λ⁴)/2 · h' h'ᵀ,
// which holds for both conventions because only h and h' enter (the convention decides which
// of sin/cos lands on east and on north; the moment formula does not care).
//
// Two conditionings are used:
//   given the truth:       m ~ N(t, Σ)  — what Mo's unbiased mean is unbiased for;
//   given the measurement: t ~ N(m, Σ)  — the posterior under a flat prior in (r, az, el), which
//                                          the debiased and the modified unbiased conversions use.
// A nested expectation E_t|m[ E_m'|t[·] ] is a single expectation with doubled variances
// (Gaussian convolution), so "average true bias/covariance" needs only moments at Σ and 2Σ.

#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>

#include <Eigen/Core>

#include <cmath>

namespace trackflow::conversion {

// Variances of the range, azimuth and elevation errors (the diagonal of the spherical covariance).
struct SphericalVariances {
  double range = 0.0;
  double azimuth = 0.0;
  double elevation = 0.0;
  SphericalVariances doubled() const { return {2.0 * range, 2.0 * azimuth, 2.0 * elevation}; }
};

// λ = E[cos w] for w ~ N(0, variance).
inline double cos_attenuation(double variance) { return std::exp(-0.5 * variance); }

// E[p(m) | t] = D p(t) with D = diag(λa λe, λa λe, λe): x and y carry one cosine of each angle
// error, z only the elevation's. Returned as the diagonal.
inline Vec3 mean_attenuation(const SphericalVariances& v) {
  const double la = cos_attenuation(v.azimuth), le = cos_attenuation(v.elevation);
  return {la * le, la * le, le};
}

struct PositionMoments {
  Vec3 mean;
  Mat3 covariance;
};

// Mean and covariance of p(r', az', el') for independent Gaussians r', az', el' centred on
// (r, az, el) with variances v. Exact (no linearisation); written as sums of positive
// semi-definite terms so that small σ's lose no precision to cancellation.
inline PositionMoments gaussian_moments(double r, double az, double el, const SphericalVariances& v,
                                        AzimuthConvention c) {
  const AzimuthBasis b = azimuth_basis(az, c);
  const Eigen::Vector2d h(b.east, b.north), hp(b.d_east, b.d_north);
  const double ce = std::cos(el), se = std::sin(el);
  const double la = cos_attenuation(v.azimuth), le = cos_attenuation(v.elevation);
  // 1-λ² = -expm1(-σ²), 1-λ⁴ = -expm1(-2σ²): exact even when σ² is below rounding of 1.
  const double a2 = -std::expm1(-v.azimuth), a4 = -std::expm1(-2.0 * v.azimuth);
  const double e2 = -std::expm1(-v.elevation), e4 = -std::expm1(-2.0 * v.elevation);

  // Cov of h(az') and of (cos el', sin el').
  const Eigen::Matrix2d Ha = 0.5 * a2 * a2 * h * h.transpose() + 0.5 * a4 * hp * hp.transpose();
  const Eigen::Vector2d ve(ce, se), vp(-se, ce);
  const Eigen::Matrix2d Ve = 0.5 * e2 * e2 * ve * ve.transpose() + 0.5 * e4 * vp * vp.transpose();

  // u = (v0·h, v1) with v = (cos el', sin el') independent of h: E[u] and Cov[u] from the
  // factor moments (E[v0²] = (λe ce)² + Ve00, E[h hᵀ] = λa² h hᵀ + Ha).
  Vec3 mean_u;
  mean_u << la * le * ce * h, le * se;
  Mat3 cov_u;
  cov_u.topLeftCorner<2, 2>() = (le * ce) * (le * ce) * Ha + Ve(0, 0) * (la * la * h * h.transpose() + Ha);
  cov_u.topRightCorner<2, 1>() = Ve(0, 1) * la * h;
  cov_u.bottomLeftCorner<1, 2>() = cov_u.topRightCorner<2, 1>().transpose();
  cov_u(2, 2) = Ve(1, 1);

  // p = r' u with r' independent of u: Cov = E[r'²] Cov[u] + Var[r'] E[u] E[u]ᵀ.
  PositionMoments m;
  m.mean = r * mean_u;
  m.covariance = (r * r + v.range) * cov_u + v.range * mean_u * mean_u.transpose();
  return m;
}

// A converted position (sensor-relative) with its covariance. The covariance with a range-rate
// measurement ρ is diag(jacobian_scale) · J(m) · Cov[(r, az, el), ρ], J the exact Jacobian at
// the measured point: by Stein's lemma Cov[g(w), ρ] = E[∇g] Cov[w, ρ] for jointly Gaussian
// errors, and E[J(t) | m] = E[J(m') | t=m] = D J(m), so the scale is the same conditioning
// applied to the Jacobian as each method applies to its position covariance.
struct ConvertedPosition {
  Vec3 position;
  Mat3 covariance;
  Vec3 jacobian_scale;
};

// Additive debiased conversion (Lerro & Bar-Shalom 1993; 3-D: Suchomski 1999). The "average
// true bias" E_t|m[ E[p(m')|t] - p(t) ] = (D - I) D p(m) is subtracted; the covariance is the
// average true covariance E_t|m[ Cov[p(m')|t] ] = C(2Σ) - D C(Σ) D (law of total variance).
inline ConvertedPosition debiased(double r, double az, double el, const SphericalVariances& v,
                                  AzimuthConvention c) {
  const Vec3 d = mean_attenuation(v);
  const Vec3 p = spherical_to_enu(r, az, el, c);
  const Mat3 c1 = gaussian_moments(r, az, el, v, c).covariance;
  const Mat3 c2 = gaussian_moments(r, az, el, v.doubled(), c).covariance;
  ConvertedPosition out;
  out.position = (Vec3::Ones() + d - d.cwiseProduct(d)).cwiseProduct(p);
  out.covariance = c2 - d.asDiagonal() * c1 * d.asDiagonal();
  out.jacobian_scale = d.cwiseProduct(d);
  return out;
}

// Multiplicative unbiased conversion (Mo et al. 1998, eq 9, 11, 12): D⁻¹ p(m), unbiased given
// the truth because E[p(m)|t] = D p(t). Covariance: the truth-conditioned covariance
// D⁻¹ Cov[p(m')|t] D⁻¹ averaged over t given m = D⁻¹ C(2Σ) D⁻¹ - C(Σ).
inline ConvertedPosition unbiased(double r, double az, double el, const SphericalVariances& v, AzimuthConvention c) {
  const Vec3 d_inv = mean_attenuation(v).cwiseInverse();
  const Mat3 c1 = gaussian_moments(r, az, el, v, c).covariance;
  const Mat3 c2 = gaussian_moments(r, az, el, v.doubled(), c).covariance;
  ConvertedPosition out;
  out.position = d_inv.cwiseProduct(spherical_to_enu(r, az, el, c));
  out.covariance = d_inv.asDiagonal() * c2 * d_inv.asDiagonal() - c1;
  out.jacobian_scale = mean_attenuation(v);
  return out;
}

// Modified unbiased conversion (Duan, Han & Li 2004): the posterior mean and covariance of the
// true position given the measurement, E[p(t)|m] = D p(m) and Cov[p(t)|m] = C(Σ). Note the
// mean multiplies by λ where Mo's divides.
inline ConvertedPosition unbiased_modified(double r, double az, double el, const SphericalVariances& v,
                                           AzimuthConvention c) {
  const PositionMoments m = gaussian_moments(r, az, el, v, c);
  return {m.mean, m.covariance, mean_attenuation(v)};
}

}  // namespace trackflow::conversion
