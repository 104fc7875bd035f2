// Purpose: the gain-transformation filter of paper 002 (eq 17-22, 35): Singer prediction and three decoupled 3-state updates in the LOS frame, gain rotated to ENU; any scalar type.
#pragma once

#include "los_frame.hpp"

namespace trackflow::gain_transform {

// State layout of motion.hpp's KinematicModel<3>: [x vx ax, y vy ay, z vz az], ENU.
constexpr int state_index(int axis, int order) { return 3 * axis + order; }

// Symmetric 3x3 covariance of one LOS axis' [position, velocity, acceleration].
template <class S>
struct AxisCov {
  S pp, pv, pa, vv, va, aa;
  S at(int i, int j) const {
    if (i > j) return at(j, i);
    const S* row0[3] = {&pp, &pv, &pa};
    if (i == 0) return *row0[j];
    if (i == 1) return j == 1 ? vv : va;
    return aa;
  }
};

// One axis of the Singer model: F = [[1, f01, f02], [0, 1, f12], [0, 0, f22]] and the discrete
// noise per unit sigma_m^2 (SingerModel::axis_noise with sigma = 1), cached per interval T.
template <class S>
struct SingerAxis {
  S f01, f02, f12, f22;
  AxisCov<S> q;
};

// What one update used and produced.
template <class S>
struct UpdateResult {
  S K[9][3];     // ENU gain on the polar innovation [r, az, el]: paper eq 35, K = blkdiag(D) K0
  S s[3];        // innovation variances in the LOS frame (m^2)
  S nu_los[3];   // innovation in LOS distance units, Lambda nu
  S nis;
};

// x = F x per axis (4 multiplications per axis).
template <class S>
void predict_state(S x[9], const SingerAxis<S>& m) {
  for (int a = 0; a < 3; ++a) {
    S& p = x[state_index(a, 0)];
    S& v = x[state_index(a, 1)];
    S& acc = x[state_index(a, 2)];
    p = p + m.f01 * v + m.f02 * acc;
    v = v + m.f12 * acc;
    acc = m.f22 * acc;
  }
}

// B = F B F' + sigma2 Q1 with F B F' written out for the Singer F: only the entries of F B that
// F B F' needs (9 multiplications), then its upper triangle (7) and the noise (6).
template <class S>
void predict_axis(AxisCov<S>& B, const SingerAxis<S>& m, const S& sigma2) {
  const S r00 = B.pp + m.f01 * B.pv + m.f02 * B.pa;  // r_ij = (F B)(i, j)
  const S r01 = B.pv + m.f01 * B.vv + m.f02 * B.va;
  const S r02 = B.pa + m.f01 * B.va + m.f02 * B.aa;
  const S r11 = B.vv + m.f12 * B.va;
  const S r12 = B.va + m.f12 * B.aa;
  const S r22 = m.f22 * B.aa;
  B.pp = r00 + m.f01 * r01 + m.f02 * r02 + sigma2 * m.q.pp;
  B.pv = r01 + m.f12 * r02 + sigma2 * m.q.pv;
  B.pa = m.f22 * r02 + sigma2 * m.q.pa;
  B.vv = r11 + m.f12 * r12 + sigma2 * m.q.vv;
  B.va = m.f22 * r12 + sigma2 * m.q.va;
  B.aa = m.f22 * r22 + sigma2 * m.q.aa;
}

// Re-expresses the blocks, kept in frame `from`, in frame `to`. With C = D_to' D_from, the
// block-diagonal part of (C ⊗ I3) P̄ (C ⊗ I3)' is B'_i = Σ_j C_ij² B_j (the dropped cross-axis
// blocks are Σ_j C_ij C_kj B_j): exact for a permutation of axes, trace-preserving, and each
// B'_i is a non-negative combination of PSD blocks, hence PSD. 90 multiplications.
template <class S>
void reframe(AxisCov<S> B[3], const S from[3][3], const S to[3][3]) {
  S c2[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const S c = to[i][0] * from[j][0] + to[i][1] * from[j][1] + to[i][2] * from[j][2];
      c2[i][j] = c * c;
    }
  AxisCov<S> out[3];
  for (int i = 0; i < 3; ++i) {
    out[i].pp = c2[i][0] * B[0].pp + c2[i][1] * B[1].pp + c2[i][2] * B[2].pp;
    out[i].pv = c2[i][0] * B[0].pv + c2[i][1] * B[1].pv + c2[i][2] * B[2].pv;
    out[i].pa = c2[i][0] * B[0].pa + c2[i][1] * B[1].pa + c2[i][2] * B[2].pa;
    out[i].vv = c2[i][0] * B[0].vv + c2[i][1] * B[1].vv + c2[i][2] * B[2].vv;
    out[i].va = c2[i][0] * B[0].va + c2[i][1] * B[1].va + c2[i][2] * B[2].va;
    out[i].aa = c2[i][0] * B[0].aa + c2[i][1] * B[1].aa + c2[i][2] * B[2].aa;
  }
  for (int i = 0; i < 3; ++i) B[i] = out[i];
}

// Measurement variances in LOS distance units, rbar = diag(Lambda R Lambda) (R's off-diagonal
// terms dropped; sim.radar's R is diagonal), plus the curvature of the angles over the predicted
// horizontal uncertainty, the covariance term of the second-order EKF as filter.ekf adds it (in
// rad^2 there; times rho^2 and r^2 here): with a = horizontal variance along the line of sight
// (u_r's and u_el's horizontal parts) and b = across it (u_az),
//   azimuth: a b / rho^2,  elevation: (z b / (r rho))^2 / 2.
// Negligible at ordinary ranges (1e-9 m^2 in paper 002's scenarios). Returns whether the azimuth
// must not be used: the zenith lies within zenith_sigmas standard deviations of the predicted
// horizontal position (rho^2 < zenith_sigmas^2 (a + b)), where the azimuth can flip by pi.
// R_diag = (sigma_r^2, sigma_az^2, sigma_el^2); z = height above the sensor. 14 multiplications, 2 divisions.
template <class S>
bool measurement_variances(const AxisCov<S> B[3], const LosFrame<S>& f, const S& z, const S R_diag[3],
                           double zenith_sigmas, S rbar[3]) {
  const S ce = f.u[2][2], se = f.u[0][2];
  const S a = ce * ce * B[0].pp + se * se * B[2].pp, b = B[1].pp;
  const S rho2 = f.rho * f.rho;
  const S k = z * b / (f.range * f.rho);
  rbar[0] = R_diag[0];
  rbar[1] = rho2 * R_diag[1] + a * b / rho2;
  rbar[2] = f.range * f.range * R_diag[2] + S(0.5) * k * k;
  return rho2 < S(zenith_sigmas * zenith_sigmas) * (a + b);
}

// The gain computation of paper 002 (eq 18-22 and 35) for measurement variances rbar (LOS
// distance units, m^2) and innovation nu (polar, azimuth already wrapped). Axis i is updated
// only if use[i]. Per axis, a 3-state filter that measures its own position:
//   s_i = B_i(0,0) + rbar_i,  k_i = B_i(:,0) / s_i,  B_i <- B_i - k_i B_i(0,:)
// (B_i(0,0) is written as k_i(0) rbar_i, the same value without the cancellation).
// K0 (eq 22, polar innovation -> LOS state) has k_i Lambda_i in column i; eq 35 rotates it:
//   K[(a, o)][i] = D(a, i) K0[(i, o)][i] = u[i][a] k_i(o) Lambda_i.
// Multiplications: 9 (k) + 18 (B) + 6 (k Lambda; Lambda_0 = 1) + 27 (D K0) = 60, and 3 divisions.
template <class S>
void decoupled_gain(AxisCov<S> B[3], const LosFrame<S>& f, const S rbar[3], const bool use[3], UpdateResult<S>& out) {
  for (int i = 0; i < 3; ++i) {
    if (!use[i]) {
      for (int a = 0; a < 3; ++a)
        for (int o = 0; o < 3; ++o) out.K[state_index(a, o)][i] = S(0.0);
      out.s[i] = B[i].pp + rbar[i];
      continue;
    }
    AxisCov<S>& b = B[i];
    const S s = b.pp + rbar[i];
    const S inv = S(1.0) / s;
    const S k0 = b.pp * inv, k1 = b.pv * inv, k2 = b.pa * inv;
    b.vv = b.vv - k1 * b.pv;
    b.va = b.va - k1 * b.pa;
    b.aa = b.aa - k2 * b.pa;
    b.pv = b.pv - k0 * b.pv;
    b.pa = b.pa - k0 * b.pa;
    b.pp = k0 * rbar[i];
    out.s[i] = s;
    const S g[3] = {i == 0 ? k0 : k0 * f.scale[i], i == 0 ? k1 : k1 * f.scale[i], i == 0 ? k2 : k2 * f.scale[i]};
    for (int a = 0; a < 3; ++a)
      for (int o = 0; o < 3; ++o) out.K[state_index(a, o)][i] = f.u[i][a] * g[o];
  }
}

// x += K nu (27 multiplications) and the NIS from the LOS innovation (2 + 6).
template <class S>
void correct_state(S x[9], const LosFrame<S>& f, const S nu[3], const bool use[3], UpdateResult<S>& out) {
  out.nis = S(0.0);
  for (int i = 0; i < 3; ++i) {
    out.nu_los[i] = i == 0 ? nu[0] : nu[i] * f.scale[i];
    if (use[i]) out.nis = out.nis + out.nu_los[i] * out.nu_los[i] / out.s[i];
  }
  for (int r = 0; r < 9; ++r) x[r] = x[r] + out.K[r][0] * nu[0] + out.K[r][1] * nu[1] + out.K[r][2] * nu[2];
}

// The ENU covariance the blocks stand for, P = blkdiag(D) P̄ blkdiag(D)' in the state layout:
// P[(a,o),(b,t)] = Σ_i D(a,i) D(b,i) B_i(o,t). Symmetric by construction and PSD (a sum of
// Kronecker products of PSD matrices). `P` is any matrix type with operator()(row, col).
// 18 + 135 multiplications (6 axis pairs; 9 or, on the diagonal, 6 entries of 3 terms each).
template <class S, class Matrix>
void enu_covariance(const AxisCov<S> B[3], const S u[3][3], Matrix& P) {
  S full[3][3][3];  // the blocks as plain 3x3 arrays
  for (int i = 0; i < 3; ++i) {
    const AxisCov<S>& b = B[i];
    const S m[3][3] = {{b.pp, b.pv, b.pa}, {b.pv, b.vv, b.va}, {b.pa, b.va, b.aa}};
    for (int o = 0; o < 3; ++o)
      for (int t = 0; t < 3; ++t) full[i][o][t] = m[o][t];
  }
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) {
      const S w0 = u[0][a] * u[0][b], w1 = u[1][a] * u[1][b], w2 = u[2][a] * u[2][b];
      for (int o = 0; o < 3; ++o)
        for (int t = (a == b ? o : 0); t < 3; ++t) {
          const S v = w0 * full[0][o][t] + w1 * full[1][o][t] + w2 * full[2][o][t];
          P(state_index(a, o), state_index(b, t)) = v;
          P(state_index(b, t), state_index(a, o)) = v;
        }
    }
}

}  // namespace trackflow::gain_transform
