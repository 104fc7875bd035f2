// Purpose: maps per-channel process noise (range jerk PSD, angular jerk PSDs) onto a filter's line-of-sight or ENU-axis intensities.
#pragma once

#include <trackflow/geometry.hpp>

#include <cmath>

namespace trackflow::adapt {

// White-jerk spectral densities per measurement channel, as paper 000 tabulates them (q_r, q_θ,
// q_φ): range in m²/s⁵, azimuth and elevation in rad²/s⁵ (the paper writes cm² and µrad²,
// leaving out the /s⁵ of a jerk PSD).
struct ChannelPsd {
  double range = 0.0, azimuth = 0.0, elevation = 0.0;
};

// Linear PSDs (m²/s⁵) along the local spherical basis at (r, el): radial, horizontal cross-range
// (an angular jerk of the azimuth moves the target by r cos(el) per radian) and vertical
// cross-range (r per radian of elevation). This is filter.ekf_spherical's q_r, q_h, q_v.
inline Vec3 line_of_sight_psd(const ChannelPsd& q, double r, double el) {
  const double rh = r * std::cos(el);
  return {q.range, rh * rh * q.azimuth, r * r * q.elevation};
}

// The same noise as an ENU jerk PSD is J diag(q) Jᵀ with J = ∂(x, y, z)/∂(r, az, el) — a full
// 3×3 matrix unless the line of sight lies along an axis. A filter with one intensity per ENU
// axis (filter.ekf) can only take its diagonal, Σ_i J_ei² q_i: the trace (total jerk power) is
// kept, the orientation of the noise ellipsoid is lost off the axes.
inline Vec3 enu_axis_psd(const ChannelPsd& q, double r, double az, double el, AzimuthConvention c) {
  const Mat3 J = spherical_to_enu_jacobian(r, az, el, c);
  return J.cwiseAbs2() * Vec3(q.range, q.azimuth, q.elevation);
}

}  // namespace trackflow::adapt
