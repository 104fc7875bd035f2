// Purpose: the decoupled constant-velocity Kalman filter of paper 001 (eq 21-27, after Fitzgerald 1985): three 2-state gains in the line-of-sight frame, state in ENU.
#pragma once

#include <trackflow/items.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>

namespace trackflow::decoupled {

using Mat2 = Eigen::Matrix2d;
using Vec2 = Eigen::Vector2d;
using Gain = Eigen::Matrix<double, 6, 3>;

// State layout of motion.hpp's ConstantVelocity: [x vx y vy z vz], ENU.
constexpr int pos(int axis) { return 2 * axis; }
constexpr int vel(int axis) { return 2 * axis + 1; }

// The line-of-sight (radar) frame at relative position d = target - sensor, as the columns of
// an orthonormal, right-handed D = [u_r u_az u_el] (ENU components):
//   u_r  = d / |d| = [cos az cos el, sin az cos el, sin el]  (azimuth from x toward y, paper eq 9)
//   u_az = [-sin az, cos az, 0]          (horizontal, toward increasing azimuth)
//   u_el = u_r x u_az = [-cos az sin el, -sin az sin el, cos el]
// These are the columns of the exact Jacobian d(x,y,z)/d(r,az,el) divided by 1, r cos el and r,
// so J R_s J' = D diag(σ_r², (r cos el σ_az)², (r σ_el)²) D': the classical converted covariance
// is diagonal in this frame. (Paper eq 11 prints a D whose angle columns lack the minus signs and
// keep a cos el factor; with eq 12's r_m σ² for (r σ)² it is not this rotation nor the Jacobian.)
// Returns false, leaving D alone, where the frame is undefined: at the sensor or straight above it.
inline bool line_of_sight_frame(const Vec3& d, Mat3& D) {
  const double r = d.norm();
  const double horizontal = std::hypot(d.x(), d.y());
  if (!(r > 0.0) || !std::isfinite(r) || horizontal <= 1e-9 * r) return false;
  const Vec3 ur = d / r;
  const Vec3 uaz(-d.y() / horizontal, d.x() / horizontal, 0.0);
  D.col(0) = ur;
  D.col(1) = uaz;
  D.col(2) = ur.cross(uaz);
  return true;
}

// What the filter used in one update, in ENU: the innovation, its covariance, the NIS.
struct UpdateResult {
  Vec3 innovation = Vec3::Zero();
  Mat3 innovation_covariance = Mat3::Zero();
  double nis = 0.0;
};

// The state x is Cartesian (ENU). The covariance is kept as the decoupled-frame covariance P̄ of
// paper eq 22/24: block-diagonal in the frame D, one 2x2 [position, velocity] block per
// line-of-sight axis (range, cross-range in azimuth, cross-range in elevation). The Cartesian
// covariance it stands for is P = D2 P̄ D2' with D2 = D ⊗ I2 (paper eq 27's blkdiag(D, D) in the
// [x y z vx vy vz] order). Why this works: with one isotropic process noise for all three axes,
// F and Q commute with any rotation, so the prediction is the same in every frame; and when R is
// diagonal in the frame of P̄'s blocks, the 6-state Kalman update splits exactly into three
// independent 2-state updates. The approximations are (i) R̄ = D' R D is replaced by its diagonal,
// (ii) when the line of sight turns, P̄'s blocks are re-expressed in the new frame keeping only the
// block diagonal (reframe()), the cross-axis terms being dropped.
class DecoupledCv {
 public:
  Vec6 x = Vec6::Zero();
  std::array<Mat2, 3> P{Mat2::Identity(), Mat2::Identity(), Mat2::Identity()};  // P̄ blocks
  Mat3 D = Mat3::Identity();

  // Two-point differencing (Bar-Shalom, Li & Kirubarajan 2001 §5.5.3) done per LOS axis with the
  // diagonals of D' R1 D and D' R2 D, D being the frame of the second point.
  void initialise(const Vec3& z1, const Mat3& R1, const Vec3& z2, const Mat3& R2, double T, const Mat3& frame) {
    D = frame;
    for (int a = 0; a < 3; ++a) {
      x(pos(a)) = z2(a);
      x(vel(a)) = (z2(a) - z1(a)) / T;
    }
    for (int i = 0; i < 3; ++i) {
      const double r2 = D.col(i).dot(R2 * D.col(i));
      const double r1 = D.col(i).dot(R1 * D.col(i));
      P[i] << r2, r2 / T, r2 / T, (r1 + r2) / (T * T);
    }
  }

  // Paper eq 21-22 with F = [[1, T], [0, 1]] and the per-axis noise Q_axis, identical on all axes.
  void predict(double T, const Mat2& Q_axis) {
    for (int a = 0; a < 3; ++a) x(pos(a)) += T * x(vel(a));
    for (auto& B : P) {
      // F B F' written out: B00 + 2T B01 + T² B11, B01 + T B11, B11.
      const double p00 = B(0, 0) + T * (2.0 * B(0, 1) + T * B(1, 1));
      const double p01 = B(0, 1) + T * B(1, 1);
      B(0, 0) = p00 + Q_axis(0, 0);
      B(0, 1) = B(1, 0) = p01 + Q_axis(0, 1);
      B(1, 1) += Q_axis(1, 1);
    }
  }

  // Re-expresses P̄ in the frame `next`. With C = next' D (direction cosines), the block-diagonal
  // part of (C ⊗ I2) P̄ (C ⊗ I2)' is B'_i = Σ_j C_ij² B_j: exact when the frames differ by a
  // permutation/sign change, and it keeps the trace of the Cartesian covariance.
  void reframe(const Mat3& next) {
    const Mat3 C = next.transpose() * D;
    std::array<Mat2, 3> B;
    for (int i = 0; i < 3; ++i) {
      B[i].setZero();
      for (int j = 0; j < 3; ++j) B[i] += (C(i, j) * C(i, j)) * P[j];
    }
    P = B;
    D = next;
  }

  // Variances of R in the decoupled frame: diag(D' R D).
  Vec3 decoupled_noise(const Mat3& R) const {
    return {D.col(0).dot(R * D.col(0)), D.col(1).dot(R * D.col(1)), D.col(2).dot(R * D.col(2))};
  }

  // Paper eq 25-26 in ENU: K = D2 K̄ D', K̄ the three per-axis gains k_i = B_i h' / (h B_i h' + r̄_i),
  // h = [1 0], placed in the rows of axis i. Returns false (nothing changed) if some r̄_i is
  // negative or h B_i h' + r̄_i is not positive (or either is not finite). Covariance per axis in
  // Joseph form,
  // B_i = (I - k_i h) B_i (I - k_i h)' + k_i r̄_i k_i'.
  bool update(const Vec3& z, const Mat3& R, UpdateResult& out) {
    const Vec3 rbar = decoupled_noise(R);
    Vec3 s;
    for (int i = 0; i < 3; ++i) {
      s(i) = P[i](0, 0) + rbar(i);
      if (!(rbar(i) >= 0.0) || !(s(i) > 0.0) || !std::isfinite(s(i))) return false;
    }
    Vec3 position(x(pos(0)), x(pos(1)), x(pos(2)));
    out.innovation = z - position;
    const Vec3 nu_bar = D.transpose() * out.innovation;
    Vec3 dpos_bar, dvel_bar;
    out.nis = 0.0;
    for (int i = 0; i < 3; ++i) {
      const Vec2 k = P[i].col(0) / s(i);
      dpos_bar(i) = k(0) * nu_bar(i);
      dvel_bar(i) = k(1) * nu_bar(i);
      out.nis += nu_bar(i) * nu_bar(i) / s(i);
      Mat2 A = Mat2::Identity();
      A.col(0) -= k;
      const Mat2 B = A * P[i] * A.transpose() + (rbar(i) * k) * k.transpose();
      P[i] = 0.5 * (B + B.transpose());
    }
    const Vec3 dpos = D * dpos_bar, dvel = D * dvel_bar;
    for (int a = 0; a < 3; ++a) {
      x(pos(a)) += dpos(a);
      x(vel(a)) += dvel(a);
    }
    out.innovation_covariance = D * s.asDiagonal() * D.transpose();
    out.innovation_covariance = 0.5 * (out.innovation_covariance + out.innovation_covariance.transpose()).eval();
    return true;
  }

  // The ENU gain K = D2 K̄ D' this state would use with R (for tests and inspection).
  Gain gain(const Mat3& R) const {
    const Vec3 rbar = decoupled_noise(R);
    Eigen::Matrix<double, 6, 3> Kbar = Eigen::Matrix<double, 6, 3>::Zero();  // decoupled frame, interleaved rows
    for (int i = 0; i < 3; ++i) Kbar.block<2, 1>(2 * i, i) = P[i].col(0) / (P[i](0, 0) + rbar(i));
    return d2() * Kbar * D.transpose();
  }

  // D2 = D ⊗ I2 in the interleaved layout.
  Mat6 d2() const {
    Mat6 M = Mat6::Zero();
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < 3; ++i) {
        M(pos(a), pos(i)) = D(a, i);
        M(vel(a), vel(i)) = D(a, i);
      }
    return M;
  }

  // P = D2 P̄ D2' in the interleaved layout: P[(a,s),(b,t)] = Σ_i D(a,i) D(b,i) B_i(s,t).
  void cartesian_covariance(Mat6& out) const {
    for (int a = 0; a < 3; ++a)
      for (int b = a; b < 3; ++b) {
        Mat2 block = Mat2::Zero();
        for (int i = 0; i < 3; ++i) block += (D(a, i) * D(b, i)) * P[i];
        out.block<2, 2>(2 * a, 2 * b) = block;
        out.block<2, 2>(2 * b, 2 * a) = block.transpose();
      }
  }
};

}  // namespace trackflow::decoupled
