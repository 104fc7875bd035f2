// Purpose: paper 002's line-of-sight frame (x0 along the LOS, y0 horizontal, z0 toward rising elevation) and its scalings to the polar measurement, for any scalar type.
#pragma once

#include <trackflow/items.hpp>

#include <cmath>

namespace trackflow::gain_transform {

// The frame at a relative position d = target - sensor (ENU), with the polar measurement h(d).
//
// Derivation (the paper's eq 9, 15, 16 have typos; this is what the tests check numerically).
// With rho = hypot(x, y) and r = |d|, the exact Jacobian of the polar -> ENU map is
//   F(X) = d(x,y,z)/d(r,az,el) = [u_r, rho u_az, r u_el] = D diag(1, rho, r) = D Lambda,
// where D = [u_r u_az u_el] is orthonormal:
//   u_r  = d / r                                          (x0: along the line of sight)
//   u_az = d(direction)/d(az), horizontal: ( y, -x, 0)/rho (north_clockwise, az = atan2(x, y))
//                                          (-y,  x, 0)/rho (x_counterclockwise, az = atan2(y, x))
//   u_el = (-x z / (r rho), -y z / (r rho), rho / r)      (z0: toward rising elevation)
// and rho = r cos(el). Hence G(X) = F(X)^-1 = Lambda^-1 D' (the Jacobian of h), and the LOS
// frame <-> polar scalings are G0 = Lambda^-1 = diag(1, 1/(r cos el), 1/r), F0 = Lambda.
// Paper eq 15/16 print diag(1, 1/r, -1/r) and diag(1, r, r): the cos(el) is missing (0.5 % at
// the circle's 5.7 deg elevation, a factor 2 at 60 deg) and the sign of the third entry is
// inconsistent with its own F0. Eq 9's second row (-y, x, 0)/rho is u_az, not d(az)/dX, which is
// u_az / rho. With these, F(X) G0(X) = D, so eq 35's blkdiag(F) blkdiag(G0) is blkdiag(D): the
// gain transformation is a rotation of the LOS-frame gain.
template <class S>
struct LosFrame {
  S u[3][3];   // u[i][a]: ENU component a of LOS axis i (0: range x0, 1: azimuth y0, 2: elevation z0); D(a, i)
  S scale[3];  // Lambda = (1, rho, r): LOS distance per unit of (range, azimuth, elevation)
  S h[3];      // the polar measurement of d: range, azimuth, elevation
  S rho, range;
};

// Valid for rho > 0 (callers check the zenith and the sensor position in double first).
// 8 multiplications, 2 divisions, 2 hypot, 2 atan2 (h(x) comes with the frame).
template <class S>
void line_of_sight_frame(const S d[3], AzimuthConvention c, LosFrame<S>& f) {
  using std::atan2;
  using std::hypot;
  const S rho = hypot(d[0], d[1]);
  const S r = hypot(rho, d[2]);
  const S inv_rho = S(1.0) / rho, inv_r = S(1.0) / r;
  const S ux = d[0] * inv_rho, uy = d[1] * inv_rho;  // horizontal unit vector toward the target
  const S ce = rho * inv_r;
  for (int a = 0; a < 3; ++a) f.u[0][a] = d[a] * inv_r;
  const S se = f.u[0][2];
  if (c == AzimuthConvention::NorthClockwise) {
    f.u[1][0] = uy;
    f.u[1][1] = -ux;
    f.h[1] = atan2(d[0], d[1]);
  } else {
    f.u[1][0] = -uy;
    f.u[1][1] = ux;
    f.h[1] = atan2(d[1], d[0]);
  }
  f.u[1][2] = S(0.0);
  f.u[2][0] = -(se * ux);
  f.u[2][1] = -(se * uy);
  f.u[2][2] = ce;
  f.scale[0] = S(1.0);
  f.scale[1] = rho;
  f.scale[2] = r;
  f.h[0] = r;
  f.h[2] = atan2(d[2], rho);
  f.rho = rho;
  f.range = r;
}

}  // namespace trackflow::gain_transform
