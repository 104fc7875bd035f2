// Purpose: the radar measurement [r, az, el(, rdot)] of the UKF's sigma points as the centre point's plus small differences: each angle difference is the atan of a small ratio (a short series), not two atan2 calls per point.
#pragma once

#include <trackflow/geometry.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <algorithm>
#include <cmath>

namespace trackflow::ukf {

// atan(num / den) when den > 0 and |num| <= den / 8: the Taylor series t - t^3/3 + ... - t^17/17,
// whose first omitted term is below 1e-18 of the result there (|t|^18 / 19 <= 8^-18 / 19), so
// it is as accurate as the library's atan2 (~1 ulp). False outside (the caller uses atan2).
inline bool small_atan(double num, double den, double& out) {
  if (!(den > 0.0) || !(std::fabs(num) <= 0.125 * den)) return false;
  const double t = num / den, t2 = t * t;
  double p = 1.0 / 17.0;
  p = p * t2 - 1.0 / 15.0;
  p = p * t2 + 1.0 / 13.0;
  p = p * t2 - 1.0 / 11.0;
  p = p * t2 + 1.0 / 9.0;
  p = p * t2 - 1.0 / 7.0;
  p = p * t2 + 1.0 / 5.0;
  p = p * t2 - 1.0 / 3.0;
  p = p * t2 + 1.0;
  out = t * p;
  return true;
}

// h = spherical_measurement<M> (spherical_measurement.hpp) at a centre d0, v0 (position and
// velocity relative to the sensor) and at points d0 + e, v0 + f near it. A point's azimuth is
// the centre's plus the angle between their horizontal directions, its elevation the centre's
// plus the angle between their (horizontal range, height) directions: arg(w conj(w0)) of the
// complex numbers w, formed from the offsets so nothing cancels. For the UKF the azimuth so
// returned is already the centre's plus the wrapped difference, as unscented_measurement makes it.
// The same values as spherical_measurement<M>(d0 + e, v0 + f) to rounding (~1 ulp of each
// element; the range as sqrt(x^2 + y^2 + z^2) instead of hypot). Where a direction is undefined
// (a point or the centre on the zenith axis or at the sensor), or the difference is not small,
// the library atan2 of the point itself is used.
template <int M>
class SphericalNearCentre {
 public:
  SphericalNearCentre(const Vec3& d0, const Vec3& v0, AzimuthConvention c)
      : d0_(d0), v0_(v0), c_(c), z0_(spherical_measurement<M>(d0, v0, c)) {
    rho0_ = std::hypot(d0.x(), d0.y());
  }
  const SphericalVec<M>& centre() const { return z0_; }

  SphericalVec<M> at(const Vec3& e, const Vec3& f) const {
    const double x = d0_.x() + e.x(), y = d0_.y() + e.y(), z = d0_.z() + e.z();
    const double rho2 = x * x + y * y, rho = std::sqrt(rho2), r = std::sqrt(rho2 + z * z);
    SphericalVec<M> h;
    h(0) = r;
    const double x0 = d0_.x(), y0 = d0_.y(), z0 = d0_.z();
    double delta = 0.0;
    if (rho0_ > 0.0 && rho > 0.0) {
      // north_clockwise: az = arg(y + i x); x_counterclockwise: az = arg(x + i y).
      const double cross = e.x() * y0 - e.y() * x0, dot = x * x0 + y * y0;
      const double num = c_ == AzimuthConvention::NorthClockwise ? cross : -cross;
      if (!small_atan(num, dot, delta)) delta = std::atan2(num, dot);
      h(1) = z0_(1) + delta;
    } else {
      const double az = c_ == AzimuthConvention::NorthClockwise ? std::atan2(x, y) : std::atan2(y, x);
      h(1) = z0_(1) + wrap_angle(az - z0_(1));
    }
    if (rho0_ > 0.0 && rho > 0.0) {
      // el = arg(rho + i z); rho - rho0 from the offsets: (rho^2 - rho0^2) / (rho + rho0).
      const double drho = (e.x() * (2.0 * x0 + e.x()) + e.y() * (2.0 * y0 + e.y())) / (rho + rho0_);
      const double num = e.z() * rho0_ - drho * z0, den = rho * rho0_ + z * z0;
      if (!small_atan(num, den, delta)) delta = std::atan2(num, den);
      h(2) = z0_(2) + delta;
    } else {
      h(2) = std::atan2(z, rho);
    }
    if constexpr (M == 4) {
      const Vec3 v = v0_ + f;
      h(3) = r > 0.0 ? (x * v.x() + y * v.y() + z * v.z()) / r : v.norm();
    }
    return h;
  }

  // The points d0 + e_k, v0 + f_k, k < count, at once: the arithmetic runs over arrays (struct of
  // arrays, no branch), which the compiler vectorises; points where a series does not apply are
  // then redone one by one with at().
  template <int K>
  struct Batch {
    int count = 0;
    double ex[K], ey[K], ez[K], fx[K], fy[K], fz[K];
    SphericalVec<M> z[K];
  };

  template <int K>
  void evaluate(Batch<K>& b) const {
    const int n = b.count;
    if (!(rho0_ > 0.0)) {  // the centre on the zenith axis (or at the sensor): no reference direction
      for (int k = 0; k < n; ++k) b.z[k] = at(Vec3(b.ex[k], b.ey[k], b.ez[k]), Vec3(b.fx[k], b.fy[k], b.fz[k]));
      return;
    }
    const double x0 = d0_.x(), y0 = d0_.y(), z0 = d0_.z(), rho0 = rho0_;
    const double sign = c_ == AzimuthConvention::NorthClockwise ? 1.0 : -1.0;
    double r[K], rho[K], az_num[K], az_den[K], el_num[K], el_den[K], az_t[K], el_t[K], rr[K];
    for (int k = 0; k < n; ++k) {
      const double ex = b.ex[k], ey = b.ey[k], ez = b.ez[k];
      const double x = x0 + ex, y = y0 + ey, z = z0 + ez;
      const double rho2 = x * x + y * y;
      rho[k] = std::sqrt(rho2);
      r[k] = std::sqrt(rho2 + z * z);
      az_num[k] = sign * (ex * y0 - ey * x0);
      az_den[k] = x * x0 + y * y0;
      // rho - rho0 directly: its rounding (an ulp of rho) moves the elevation by ~1e-16 rad.
      el_num[k] = ez * rho0 - (rho[k] - rho0) * z0;
      el_den[k] = rho[k] * rho0 + z * z0;
      // One division for the three quotients (1/a = b c / (a b c)): divisions are what the
      // sigma points wait for, and a b c stays far from overflow (r^5 < 1e40 for any radar range).
      const double inv = 1.0 / (az_den[k] * el_den[k] * r[k]);
      const double t_az = az_num[k] * (el_den[k] * r[k] * inv), t_el = el_num[k] * (az_den[k] * r[k] * inv);
      az_t[k] = t_az;
      el_t[k] = t_el;
      if constexpr (M == 4)
        rr[k] = (x * (v0_.x() + b.fx[k]) + y * (v0_.y() + b.fy[k]) + z * (v0_.z() + b.fz[k])) *
                (az_den[k] * el_den[k] * inv);
    }
    double az[K], el[K];
    series_atan(az_t, az, n);
    series_atan(el_t, el, n);
    for (int k = 0; k < n; ++k) {
      const bool ok = rho[k] > 0.0 && az_den[k] > 0.0 && std::fabs(az_num[k]) <= 0.125 * az_den[k] && el_den[k] > 0.0 &&
                      std::fabs(el_num[k]) <= 0.125 * el_den[k] && (M == 3 || r[k] > 0.0);
      if (!ok) {
        b.z[k] = at(Vec3(b.ex[k], b.ey[k], b.ez[k]), Vec3(b.fx[k], b.fy[k], b.fz[k]));
        continue;
      }
      b.z[k](0) = r[k];
      b.z[k](1) = z0_(1) + az[k];
      b.z[k](2) = z0_(2) + el[k];
      if constexpr (M == 4) b.z[k](3) = rr[k];
    }
  }

 private:
  // small_atan's series over arrays of t = num / den (no check: the caller redoes the points
  // outside its range), cut where the terms left out stay below 2^-56 of the result for the
  // largest |t| of the batch: up to t^5 / 5 for |t| <= 1e-3 (t^7 / 7 is then below 1.5e-19 of t;
  // sigma points within a few kilometres at 100 km and more), up to t^9 / 9 for |t| <= 0.0158,
  // else the full series up to t^17 / 17.
  static void series_atan(const double* t_in, double* out, int n) {
    double t2max = 0.0;
    for (int k = 0; k < n; ++k) t2max = std::max(t2max, t_in[k] * t_in[k]);
    if (t2max <= 1e-6) {
      for (int k = 0; k < n; ++k) {
        const double t = t_in[k], t2 = t * t;
        out[k] = t * ((0.2 * t2 - 1.0 / 3.0) * t2 + 1.0);
      }
      return;
    }
    if (t2max <= 2.5e-4) {
      for (int k = 0; k < n; ++k) {
        const double t = t_in[k], t2 = t * t;
        double p = 1.0 / 9.0;
        p = p * t2 - 1.0 / 7.0;
        p = p * t2 + 1.0 / 5.0;
        p = p * t2 - 1.0 / 3.0;
        p = p * t2 + 1.0;
        out[k] = t * p;
      }
      return;
    }
    for (int k = 0; k < n; ++k) {
      const double t = t_in[k], t2 = t * t;
      double p = 1.0 / 17.0;
      p = p * t2 - 1.0 / 15.0;
      p = p * t2 + 1.0 / 13.0;
      p = p * t2 - 1.0 / 11.0;
      p = p * t2 + 1.0 / 9.0;
      p = p * t2 - 1.0 / 7.0;
      p = p * t2 + 1.0 / 5.0;
      p = p * t2 - 1.0 / 3.0;
      p = p * t2 + 1.0;
      out[k] = t * p;
    }
  }

  Vec3 d0_, v0_;
  AzimuthConvention c_;
  SphericalVec<M> z0_;
  double rho0_ = 0.0;
};

}  // namespace trackflow::ukf
